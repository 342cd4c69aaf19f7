"""What every model route shares: settings and runtime from app.state, the limits that depend on them, and
the bounded, timed run of the work in a worker thread.

Concurrent small requests are read as one batch here too (`Coalescer`, the section below).
"""

from __future__ import annotations

import asyncio
import functools
import threading
import time
from collections.abc import Callable, Hashable, Sequence
from dataclasses import dataclass, field
from typing import Annotated, Any, Generic, TypeAlias, TypeVar, cast

import anyio
import numpy as np
from fastapi import Depends, Request
from fastapi.responses import Response
from starlette.exceptions import HTTPException

from curve_vae.inference.model.graphs import Cancelled, CancelToken, cancellable
from curve_vae.inference.reading import Reading
from curve_vae.inference.results import Encoding, Reconstruction, split_encoding, split_reconstruction
from curve_vae.inference.runtime import CurveRuntime
from curve_vae.service.metrics import Metrics, multiprocess_mode
from curve_vae.service.settings import Settings

T = TypeVar("T")


def settings_of(request: Request) -> Settings:
    return request.app.state.settings


def runtime_of(request: Request) -> CurveRuntime:
    state = request.app.state
    if getattr(state, "failed", None):
        raise HTTPException(503, f"the model cannot serve: {state.failed}")
    if not state.ready or state.runtime is None:
        raise HTTPException(503, "the model is not loaded yet; GET /ready answers 200 once it is")
    return state.runtime


async def _settings(request: Request) -> Settings:
    return settings_of(request)


async def warmed(request: Request) -> None:
    """Returns once the model's warm-up is over: a request that comes while it runs (a page opened at once, a client
    that did not wait for /ready) waits for it (service.app._warm_then_serve)."""
    warming = getattr(request.app.state, "warming", None)  # an app built without the lifespan's state has none
    if warming is not None and not warming.done():
        await asyncio.shield(warming)


async def _runtime(request: Request) -> CurveRuntime:
    await warmed(request)
    return runtime_of(request)


# Async dependencies: FastAPI runs a plain `def` dependency on a worker thread, two thread hops per request for
# what is an attribute read (measured: a fifth of a single-curve request's server CPU).
SettingsDep = Annotated[Settings, Depends(_settings)]
RuntimeDep = Annotated[CurveRuntime, Depends(_runtime)]


async def in_executor(request: Request, fn: Callable[..., T], *args: Any, token: CancelToken | None = None) -> T:
    """`fn(*args)` on one of the app's inference threads (at most one inference per slot at once, first come
    first served), under `token` when given: cancelled, the work stops at its next checkpoint
    (inference.model.graphs)."""

    def run() -> T:
        if token is None:
            return fn(*args)
        token.check()  # abandoned while it queued: never starts
        with cancellable(token):
            return fn(*args)

    return await asyncio.wrap_future(request.app.state.executor.submit(run))


#: How often a running request looks whether its client has gone.
DISCONNECT_POLL_S = 0.05


async def _watch_disconnect(request: Request, token: CancelToken) -> None:
    """Cancel `token` once the client has disconnected (polling Starlette's receive channel)."""
    while not token.cancelled:
        if await request.is_disconnected():
            token.cancel("the client disconnected")
            return
        await asyncio.sleep(DISCONNECT_POLL_S)


def coalescer_of(request: Request) -> Coalescer[Read] | None:
    """The app's coalescer of concurrent /encode and /reconstruct requests, None where CURVE_VAE_COALESCE_CURVES=0."""
    return getattr(request.app.state, "coalescer", None)


async def coalesced(
    request: Request, route: str, key: Hashable, curves: list[np.ndarray], render: Callable[[Any], Response]
) -> Response:
    """`run_inference` of a job the app's coalescer may read together with other requests' (inference.coalescing):
    registered before it queues, so requests that queue together are read together; `render` builds the response
    from this request's own part. Without a coalescer, or with more than half a batch of curves (it gains little
    from company, and would hold the coalescer's readers from the small requests), the job is read alone."""
    runtime = runtime_of(request)  # 503 until the model is loaded
    coalescer = coalescer_of(request)
    if coalescer is None or len(curves) > coalescer.max_curves // 2:
        return await run_inference(request, route, len(curves), lambda: render(read_alone(runtime, key, curves)))
    job = coalescer.submit(key, curves)
    try:
        return await run_inference(request, route, len(curves), lambda: render(coalescer.result(job)), token=job.token)
    finally:
        coalescer.forget(job)


async def run_inference(
    request: Request, route: str, batch: int, work: Callable[[], Response], *, token: CancelToken | None = None
) -> Response:
    """Run `work` (inference and JSON rendering) on an inference thread, never on the event loop; timed, and at
    most one per inference slot (CURVE_VAE_INFERENCE_CONCURRENCY) at once.

    Bounded both ways: with `slots + max_queue` requests already in here, a new one is answered 503 with
    Retry-After at once instead of joining an ever longer queue; one that takes longer than `request_timeout`
    seconds (queueing included) is answered 504. Either way, and when the client disconnects, the work is cancelled:
    its thread stops at the next chunk boundary and the slot is free for the next request. `token`: the request's
    own, where its work was registered under it before (a coalesced job's).
    """
    settings: Settings = request.app.state.settings
    state = request.app.state
    if state.pending >= state.slots + settings.max_queue:
        raise HTTPException(
            503,
            f"busy: {state.pending} requests are running or queued ({state.slots} inference slots, "
            f"CURVE_VAE_INFERENCE_CONCURRENCY, + CURVE_VAE_MAX_QUEUE {settings.max_queue}); retry in a moment",
            headers={"Retry-After": "1"},
        )
    metrics: Metrics = state.metrics
    metrics.batch_size.labels(route).observe(batch)
    state.pending += 1
    start = time.perf_counter()
    token = token or CancelToken()
    watcher = asyncio.ensure_future(_watch_disconnect(request, token))
    try:
        with anyio.fail_after(settings.request_timeout or None):
            return await in_executor(request, work, token=token)
    except TimeoutError:
        token.cancel("past CURVE_VAE_REQUEST_TIMEOUT")
        raise HTTPException(
            504, f"the request took longer than {settings.request_timeout:g} s (CURVE_VAE_REQUEST_TIMEOUT); send less"
        ) from None
    except Cancelled:
        metrics.cancelled.labels(route).inc()
        raise HTTPException(499, f"cancelled: {token.reason}") from None
    finally:
        token.cancel("the request ended")  # a still-running thread (a timeout) stops at its next checkpoint
        watcher.cancel()
        state.pending -= 1
        metrics.inference.labels(route).observe(time.perf_counter() - start)
        if multiprocess_mode():  # a scrape may reach another worker: this one's gauges must be current
            metrics.mirror(state.runtime)


# Concurrent small requests read as one batch: the default reading of a curve costs less a curve in company (16 ms
# alone, 10 ms in a batch of eight on this project's CPU: the natural-spacing fit, the ranker and the placement are
# vectorised over a batch, and their per-call overhead is paid once), so requests that queue for an inference thread
# at the same moment are read together and each gets its own part back.
#
# Flat combining, without waiting for company: every request registers its job, then queues for an inference thread
# as before. The thread that picks a job up runs it together with every other registered job of the same options not
# yet taken (up to `max_curves` curves); a job already taken by another thread's batch waits for it, and while it
# waits its thread runs the next batch of untaken jobs, if any. A request to an idle server runs alone at once —
# nothing is added to its latency — and under load the batches grow with the queue.
#
# - Only jobs with equal options (the reading, `n_points`) share a batch; a job larger than `max_curves` runs alone.
# - Right after a batch ends its clients are answered and ask again within a few milliseconds: the next batch waits
#   up to `hold` (5 ms) for as many jobs as the last had, instead of starting with the first to come back while the
#   rest queue behind it (under load, single-curve batches gave way to batches of the connections' number).
# - At most `readers` batches are read at once (the service: the CPUs of a worker, so one on 2 cores with 2 workers):
#   a thread that would start another waits, and the jobs queueing meanwhile make the next batch larger. Two batches
#   sharing one core cost more than one of both (measured: single-curve requests on 16 connections, 132 requests/s
#   with a batch per inference thread, 156 with one per worker; docs/BENCHMARKS.md).
# - A failing batch (a bad curve in one job) is run again job by job, so an error names its own request's curve.
# - A batch is cancelled only when every job in it is (each job's token, inference.model.graphs); a job abandoned
# before it
#   was taken is never read.
# - Answers equal the lone request's to rounding: onnxruntime may round a batch's rows differently, so where two
#   candidate readings tie to float32 rounding either may be kept.
#

R = TypeVar("R")


class _Joint(CancelToken):
    """Cancelled once every one of `tokens` is: a batch goes on while any of its requests still wants an answer."""

    def __init__(self, tokens: Sequence[CancelToken]) -> None:
        super().__init__()
        self.tokens = tokens

    @property
    def cancelled(self) -> bool:
        return all(t.cancelled for t in self.tokens)

    def check(self) -> None:
        if self.cancelled:
            raise Cancelled(self.tokens[0].reason)


@dataclass(eq=False)
class Job(Generic[R]):
    """One request's curves and options, and, once read, its result or error."""

    key: Hashable
    curves: Sequence[np.ndarray]
    token: CancelToken = field(default_factory=CancelToken)
    taken: bool = False
    done: threading.Event = field(default_factory=threading.Event)
    result: R | None = None
    error: BaseException | None = None

    def finish(self, result: R | None = None, error: BaseException | None = None) -> None:
        self.result, self.error = result, error
        self.done.set()


class Coalescer(Generic[R]):
    """Jobs of equal keys read together by `read(key, curves)`, whose result `split(result, sizes)` cuts into each
    job's part (in order)."""

    def __init__(
        self,
        read: Callable[[Hashable, list[np.ndarray]], R],
        split: Callable[[R, list[int]], list[R]],
        *,
        max_curves: int = 32,
        readers: int | None = None,
        hold: float = 0.005,
        observe: Callable[[int, int], None] | None = None,
    ) -> None:
        self._read, self._split, self.max_curves = read, split, max_curves
        self.readers = readers  # batches read at once (None: one per thread that asks)
        self.hold = hold  # seconds a batch may wait, right after one ended, for as many jobs as it had
        self._reading = 0
        self._ended, self._last = -1e9, 0  # when the last batch ended (time.monotonic), and its jobs
        self._observe = observe  # (jobs, curves) of each batch run: the service's histogram
        self._changed = threading.Condition()  # a job registered or a batch finished
        self._pending: list[Job[R]] = []

    def submit(self, key: Hashable, curves: Sequence[np.ndarray], token: CancelToken | None = None) -> Job[R]:
        """Register a job (on the event loop, before it queues for an inference thread)."""
        job: Job[R] = Job(key, curves, token or CancelToken())
        with self._changed:
            self._pending.append(job)
            self._changed.notify_all()
        return job

    def forget(self, job: Job[R]) -> None:
        """A job whose request has ended (answered, timed out, abandoned) leaves the register."""
        with self._changed:
            if job in self._pending:
                self._pending.remove(job)

    def result(self, job: Job[R]) -> R:
        """`job`'s result (on an inference thread): read now with the other untaken jobs of its key, or waited for
        while this thread reads the batches of jobs still untaken."""
        while True:
            with self._changed:
                batch = self._next(job)
            if batch is None:
                break
            try:
                self._run(batch)
            finally:
                for j in batch:  # an error past Exception (KeyboardInterrupt) still ends every job of the batch
                    if not j.done.is_set():
                        j.finish(error=Cancelled("the batch reading this request stopped"))
                with self._changed:
                    self._reading -= 1
                    self._ended, self._last = time.monotonic(), len(batch)
                    self._changed.notify_all()
        if job.error is not None:
            raise job.error
        assert job.result is not None
        return job.result

    def _live(self) -> list[Job[R]]:
        return [j for j in self._pending if not j.taken and not j.token.cancelled]

    def _next(self, job: Job[R]) -> list[Job[R]] | None:
        """What the thread serving `job` reads next (under the lock): `job` with the untaken jobs of its key; once
        another batch has taken it, the oldest untaken job's batch, or nothing until one comes; None once it is
        done."""
        while not job.done.is_set():
            if not job.taken and job.token.cancelled:  # abandoned: read alone, which stops at once
                return self._take(job, alone=True)
            if self.readers is None or self._reading < self.readers:
                held = self._held()
                if held > 0:
                    self._changed.wait(held)
                    continue
                if not job.taken:
                    return self._take(job)
                live = self._live()
                if live:
                    return self._take(live[0])
            self._changed.wait()
        return None

    def _held(self) -> float:
        """Seconds a new batch should still wait (under the lock): right after a batch ended, its requests' clients
        are being answered and will ask again, so a batch started at once would be one of the first to come back and
        the rest would wait for it. Up to `hold` after a batch ended, until as many jobs wait as it had."""
        left = self._ended + self.hold - time.monotonic()
        return left if left > 0 and len(self._live()) < self._last else 0.0

    def _take(self, first: Job[R], *, alone: bool = False) -> list[Job[R]]:
        """`first` and (unless alone) the untaken jobs of its key, up to max_curves curves, taken off the register."""
        batch, count = [first], len(first.curves)
        for j in [] if alone else self._live():
            if j is not first and j.key == first.key and count + len(j.curves) <= self.max_curves:
                batch.append(j)
                count += len(j.curves)
        self._reading += 1
        for j in batch:
            j.taken = True
            if j in self._pending:  # `first` may have been forgotten (its request ended): it is read alone
                self._pending.remove(j)
        return batch

    def _run(self, batch: list[Job[R]]) -> None:
        if len(batch) > 1:
            curves = [c for j in batch for c in j.curves]
            try:
                with cancellable(_Joint([j.token for j in batch])):
                    parts = self._split(self._read(batch[0].key, curves), [len(j.curves) for j in batch])
            except Exception:
                pass  # job by job below: an error names its own request's curve
            else:
                if self._observe is not None:
                    self._observe(len(batch), len(curves))
                for j, part in zip(batch, parts):
                    j.finish(part)
                return
        for j in batch:
            try:
                with cancellable(j.token):
                    j.token.check()
                    part = self._read(j.key, list(j.curves))
            except Exception as e:
                j.finish(error=e)
            else:
                if self._observe is not None:
                    self._observe(1, len(j.curves))
                j.finish(part)


#: What a runtime's coalescer reads: `/encode`'s and `/reconstruct`'s results.
Read: TypeAlias = Encoding | Reconstruction


def runtime_coalescer(
    runtime: CurveRuntime,
    *,
    max_curves: int = 32,
    readers: int | None = None,
    observe: Callable[[int, int], None] | None = None,
) -> Coalescer[Read]:
    """A coalescer of `runtime.encode` and `runtime.reconstruct` calls: jobs keyed `(kind, reading, n_points)`,
    kind "encode" or "reconstruct" (`encode_key`, `reconstruct_key`)."""

    def split(result: Read, sizes: list[int]) -> list[Read]:
        parts = split_encoding(result, sizes) if isinstance(result, Encoding) else split_reconstruction(result, sizes)
        return list[Read](parts)  # a list of one kind, typed as either

    read = functools.partial(read_alone, runtime)
    return Coalescer(read, split, max_curves=max_curves, readers=readers, observe=observe)


def read_alone(runtime: CurveRuntime, key: Hashable, curves: Sequence[np.ndarray]) -> Read:
    """What a job of `key` (`encode_key`, `reconstruct_key`) reads, without company."""
    kind, reading, n_points = cast(tuple[str, Reading, int | None], key)  # encode_key's or reconstruct_key's
    if kind == "encode":
        return runtime.encode(curves, reading)
    return runtime.reconstruct(curves, reading, n_points=n_points)


def encode_key(reading: Reading) -> tuple[str, Reading, None]:
    return ("encode", reading, None)


def reconstruct_key(reading: Reading, n_points: int | None) -> tuple[str, Reading, int | None]:
    return ("reconstruct", reading, n_points)
