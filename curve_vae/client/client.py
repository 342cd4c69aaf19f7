"""`Client` and `AsyncClient`: one method per endpoint, numpy arrays in and out, safe retries, streamed /augment.

    with Client("http://127.0.0.1:8000") as c:
        rec = c.reconstruct(curves)                        # Reconstructed: curves, mse, closeness, splines, model
        for chunk in c.augment_chunks(seeds, 100_000, seed=1, chunk=4096):
            train_on(chunk.stacked())                      # (4096, n, 2) float32, items chunk.offset …

One curve (an (n, 2) array) goes as a batch of one (client.inputs). Large batches of curves of one length go as
`.npy` bodies by themselves; answers are parsed into result objects (client.results, client.design) that carry the
model that made them. What is retried: a dropped or refused connection, a timeout, 503 (a full queue; its
Retry-After is respected) and 429, up to `retries` times with exponential backoff and jitter; never a 4xx, which
raises `ApiError` with the service's status, field and message at once.
"""

from __future__ import annotations

import asyncio
import random
import time
from collections.abc import AsyncIterator, Iterator, Sequence
from typing import Any

import httpx
import numpy as np

from curve_vae.client import calls as k
from curve_vae.client.endpoints import Endpoints, augment_fields
from curve_vae.client.errors import ApiError, RetriesExhausted
from curve_vae.client.inputs import CurvesLike, as_batch
from curve_vae.client.results import Augmented, ModelRef
from curve_vae.inference.choices import FrameMode, Pose, Spacing

RETRY_STATUS = (429, 503)
DEFAULT_CHUNK = 2048


def fresh_seed() -> int:
    """A seed for a sequence the caller gave none for: every chunk of it is drawn with this one."""
    return int(np.random.SeedSequence().generate_state(1, np.uint64)[0] >> np.uint64(11))


class _Policy:
    """When to try again, and how long to wait first."""

    def __init__(self, retries: int, backoff: float, max_backoff: float) -> None:
        self.retries, self.backoff, self.max_backoff = retries, backoff, max_backoff

    def wait(self, attempt: int, response: httpx.Response | None) -> float:
        after = response.headers.get("retry-after") if response is not None else None
        if after:
            try:
                return min(float(after), self.max_backoff)
            except ValueError:
                pass
        return min(self.max_backoff, self.backoff * 2**attempt) * random.uniform(0.5, 1.0)


def _headers(api_key: str | None) -> dict[str, str]:
    return {"Authorization": f"Bearer {api_key}"} if api_key else {}


def _request(call: k.Call) -> dict[str, Any]:
    return {
        "method": call.method,
        "path": call.path,
        "content": call.body(),
        "params": call.params or None,
        "headers": {"Content-Type": call.content_type} if call.body() is not None else {},
    }


class Client(Endpoints):
    """A curve-vae service over HTTP, synchronously (httpx). `transport`: an httpx transport in place of the
    network's (tests use it to drop connections)."""

    def __init__(
        self,
        url: str = "http://127.0.0.1:8000",
        *,
        api_key: str | None = None,
        timeout: float = 120.0,
        retries: int = 4,
        backoff: float = 0.25,
        max_backoff: float = 10.0,
        transport: httpx.BaseTransport | None = None,
    ) -> None:
        self.url = url.rstrip("/")
        self.policy = _Policy(retries, backoff, max_backoff)
        self._http = httpx.Client(base_url=self.url, timeout=timeout, headers=_headers(api_key), transport=transport)
        self._model: ModelRef | None = None

    def __enter__(self) -> Client:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def close(self) -> None:
        self._http.close()

    def send(self, method: str, path: str, **kw: Any) -> httpx.Response:
        """One request, retried as the module docstring says; the response of a success, else ApiError."""
        last: Exception | None = None
        for attempt in range(self.policy.retries + 1):
            response = None
            try:
                response = self._http.request(method, path, **kw)
                response.read()
                if response.status_code < 400:
                    return response
                if response.status_code not in RETRY_STATUS:
                    raise ApiError.from_response(response.status_code, response.content)
                last = ApiError.from_response(response.status_code, response.content)
            except httpx.TransportError as e:  # refused, dropped, timed out: the request had no answer
                last = e
            if attempt < self.policy.retries:
                time.sleep(self.policy.wait(attempt, response))
        raise _exhausted(last, self.policy.retries)

    def model(self) -> dict[str, Any]:
        """GET /model: what the server serves."""
        info = self.send("GET", "/model").json()
        self._model = ModelRef.from_info(info, self.url)
        return info

    def ready(self) -> bool:
        """Whether GET /ready answers 200 (one try, no retries)."""
        try:
            return self._http.get("/ready").status_code == 200
        except httpx.TransportError:
            return False

    def model_ref(self) -> ModelRef:
        if self._model is None:
            self.model()
        assert self._model is not None
        return self._model

    def _call(self, call: k.Call) -> Any:
        model = self.model_ref()
        response = self.send(**_request(call))
        return call.parse(response.content, model, response.headers)

    def augment_chunks(
        self,
        curves: CurvesLike,
        count: int,
        *,
        chunk: int = DEFAULT_CHUNK,
        seed: int | None = None,
        offset: int = 0,
        mode=None,
        neighbours=None,
        frame: FrameMode | None = None,
        pose: Pose | None = None,
        spacing: Spacing | None = None,
        looks: int | None = None,
        refine: int | None = None,
        n_points=None,
    ) -> Iterator[Augmented]:
        """Items offset … offset + count - 1 of a seeded augmentation sequence, `chunk` curves at a time, each a .npy
        request of its own (float32 curves; sources and weights: `augment`, JSON). A chunk whose connection drops
        is asked again from its offset; the curves are the same whatever the chunk size (item i depends on the seed
        and i alone). Without a seed one is drawn, and every chunk carries it. One curve is refused at once (a
        mix needs two), before the first chunk is asked for."""
        seeds = as_batch(curves, "augment_chunks", at_least=2)
        seed = fresh_seed() if seed is None else seed
        fields = augment_fields(mode, seed, neighbours, k.reading(frame, pose, spacing, looks, refine), n_points)
        return self._chunks(seeds, count, chunk, offset, seed, fields)

    def _chunks(
        self, curves: Sequence[Any], count: int, chunk: int, offset: int, seed: int, fields: dict[str, Any]
    ) -> Iterator[Augmented]:
        for start in range(offset, offset + count, chunk):
            n = min(chunk, offset + count - start)
            out = self._call(k.augment_call(curves, {"count": n, "offset": start, **fields}, npy=True))
            yield Augmented(self.model_ref(), list(out), seed=seed, offset=start)


class AsyncClient(Endpoints):
    """The same as `Client`, for asyncio: every endpoint method is a coroutine, `augment_chunks` an async
    iterator."""

    def __init__(
        self,
        url: str = "http://127.0.0.1:8000",
        *,
        api_key: str | None = None,
        timeout: float = 120.0,
        retries: int = 4,
        backoff: float = 0.25,
        max_backoff: float = 10.0,
        transport: httpx.AsyncBaseTransport | None = None,
    ) -> None:
        self.url = url.rstrip("/")
        self.policy = _Policy(retries, backoff, max_backoff)
        self._http = httpx.AsyncClient(
            base_url=self.url, timeout=timeout, headers=_headers(api_key), transport=transport
        )
        self._model: ModelRef | None = None

    async def __aenter__(self) -> AsyncClient:
        return self

    async def __aexit__(self, *exc: object) -> None:
        await self.aclose()

    async def aclose(self) -> None:
        await self._http.aclose()

    async def send(self, method: str, path: str, **kw: Any) -> httpx.Response:
        last: Exception | None = None
        for attempt in range(self.policy.retries + 1):
            response = None
            try:
                response = await self._http.request(method, path, **kw)
                await response.aread()
                if response.status_code < 400:
                    return response
                if response.status_code not in RETRY_STATUS:
                    raise ApiError.from_response(response.status_code, response.content)
                last = ApiError.from_response(response.status_code, response.content)
            except httpx.TransportError as e:
                last = e
            if attempt < self.policy.retries:
                await asyncio.sleep(self.policy.wait(attempt, response))
        raise _exhausted(last, self.policy.retries)

    async def model(self) -> dict[str, Any]:
        info = (await self.send("GET", "/model")).json()
        self._model = ModelRef.from_info(info, self.url)
        return info

    async def ready(self) -> bool:
        try:
            return (await self._http.get("/ready")).status_code == 200
        except httpx.TransportError:
            return False

    async def model_ref(self) -> ModelRef:
        if self._model is None:
            await self.model()
        assert self._model is not None
        return self._model

    async def _call(self, call: k.Call) -> Any:
        model = await self.model_ref()
        response = await self.send(**_request(call))
        return call.parse(response.content, model, response.headers)

    def augment_chunks(
        self,
        curves: CurvesLike,
        count: int,
        *,
        chunk: int = DEFAULT_CHUNK,
        seed: int | None = None,
        offset: int = 0,
        mode=None,
        neighbours=None,
        frame: FrameMode | None = None,
        pose: Pose | None = None,
        spacing: Spacing | None = None,
        looks: int | None = None,
        refine: int | None = None,
        n_points=None,
    ) -> AsyncIterator[Augmented]:
        """See `Client.augment_chunks`: an async iterator (`async for chunk in c.augment_chunks(…)`)."""
        seeds = as_batch(curves, "augment_chunks", at_least=2)
        seed = fresh_seed() if seed is None else seed
        fields = augment_fields(mode, seed, neighbours, k.reading(frame, pose, spacing, looks, refine), n_points)
        return self._chunks(seeds, count, chunk, offset, seed, fields)

    async def _chunks(
        self, curves: Sequence[Any], count: int, chunk: int, offset: int, seed: int, fields: dict[str, Any]
    ) -> AsyncIterator[Augmented]:
        for start in range(offset, offset + count, chunk):
            n = min(chunk, offset + count - start)
            out = await self._call(k.augment_call(curves, {"count": n, "offset": start, **fields}, npy=True))
            yield Augmented(await self.model_ref(), list(out), seed=seed, offset=start)


def _exhausted(last: Exception | None, retries: int) -> ApiError:
    if isinstance(last, ApiError):
        return RetriesExhausted(last.status, f"{last.detail} (after {retries} retries)", last.errors)
    return RetriesExhausted(0, f"no answer after {retries} retries: {type(last).__name__}: {last}")
