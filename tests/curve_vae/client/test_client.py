"""curve_vae.client.client: against a live server, each method against the raw HTTP answer, streamed augmentation,
retries, errors; against a stand-in transport (httpx.MockTransport), what is retried and how often, what is not,
the key sent, and the requests of a streamed augmentation."""

from __future__ import annotations

import asyncio
import io
import json
import threading
import time

import httpx
import numpy as np
import pytest

from curve_vae.client import ApiError, AsyncClient, Client, RetriesExhausted, fresh_seed
from tests.helpers import ONE_SLOT, bspline_curves

C1 = [[0, 0], [1, 2], [2.5, 3.2], [4, 3.5], [5.5, 3], [7, 1.5], [8, 0]]
C2 = [[0, 0], [1.5, 0.5], [3, 2], [4, 4], [5, 6.5], [6.5, 8], [8, 8.5]]
C3 = [[0, 4], [2, 5], [4, 4], [6, 2], [8, 1], [10, 2], [12, 4]]
PROFILE = [[0, 0], [3, 0], [4, 1], [3, 3], [0, 5]]


def raw(url: str, path: str, body: dict) -> dict:
    r = httpx.post(url + path, json=body, timeout=60)
    assert r.status_code == 200, r.text
    return r.json()


def test_every_method_gives_the_raw_answer_as_arrays(live_server):
    url = live_server.url
    with Client(url) as c:
        assert c.ready()
        info = c.model()
        assert info["latent_dim"] == 32
        enc = c.encode([C1, C2])
        want = raw(url, "/encode", {"curves": [C1, C2]})
        np.testing.assert_array_equal(enc.mean, want["mean"])
        assert (
            enc.frames == want["frames"] and enc.model.sha256["encoder.onnx"] == info["files"]["encoder.onnx"]["sha256"]
        )
        dec = c.decode(enc.mean, frames=enc.frames, n_points=20)
        np.testing.assert_array_equal(
            dec.curves,
            raw(url, "/decode", {"latents": want["mean"], "frames": want["frames"], "n_points": 20})["curves"],
        )
        rec = c.reconstruct([C1, C2[:5]], output="both")
        want = raw(url, "/reconstruct", {"curves": [C1, C2[:5]], "output": "both"})
        assert [len(x) for x in rec.curves] == [7, 5] and rec.splines == want["splines"]
        np.testing.assert_array_equal(rec.mse, want["mse"])
        mix = c.interpolate([C1, C2], steps=3, metrics=True)
        want = raw(url, "/interpolate", {"curves": [C1, C2], "steps": 3, "metrics": True})
        np.testing.assert_array_equal(mix.curves, want["curves"])
        assert mix.metrics == want["metrics"] and mix.weights.tolist() == want["weights"]
        s = c.sample(4, seed=3, n_points=30)
        np.testing.assert_array_equal(s.curves, raw(url, "/sample", {"count": 4, "seed": 3, "n_points": 30})["curves"])
        page = c.augment([C1, C2, C3], 5, mode="triplet", seed=2)
        want = raw(url, "/augment", {"curves": [C1, C2, C3], "count": 5, "mode": "triplet", "seed": 2})
        np.testing.assert_array_equal(page.curves, want["curves"])
        assert page.sources.tolist() == want["sources"] and page.seed == 2
        assert c.fit([C1], n_ctrl=5).json() == raw(url, "/fit", {"curves": [C1], "n_ctrl": 5})
        mesh = c.revolve(PROFILE, segments=12)
        want = httpx.post(url + "/revolve", json={"curve": PROFILE, "segments": 12})
        assert mesh.data == want.content and mesh.media_type == want.headers["content-type"]
        assert (mesh.n_vertices, mesh.n_faces) == (
            int(want.headers["x-mesh-vertices"]),
            int(want.headers["x-mesh-faces"]),
        )


def test_a_large_batch_goes_as_npy_and_answers_the_same(live_server):
    curves = bspline_curves(20, 161, seed=2)  # 3,220 points: above the client's .npy threshold
    sent: list[str] = []

    def record(request: httpx.Request) -> None:
        sent.append(request.headers.get("content-type", ""))

    with Client(live_server.url) as c:
        c._http.event_hooks["request"] = [record]
        rec = c.reconstruct(list(curves), pose="as_is")
        small = c.reconstruct(list(curves[:2]), pose="as_is")
    assert sent[-2:] == ["application/x-npy", "application/json"]
    np.testing.assert_allclose(rec.curves[:2], small.curves, atol=1e-9)


@pytest.mark.parametrize("chunk", [1, 7, 64])
def test_the_augment_iterator_gives_the_json_pages_curves_whatever_the_chunk(live_server, chunk):
    seeds = [C1, C2, C3]
    with Client(live_server.url) as c:
        streamed = np.concatenate([a.curves for a in c.augment_chunks(seeds, 100, seed=5, chunk=chunk, n_points=40)])
        paged = np.concatenate([c.augment(seeds, 50, seed=5, offset=o, n_points=40).curves for o in (0, 50)])
    np.testing.assert_allclose(streamed, paged, atol=1e-5)  # float32 .npy against float64 JSON


class _Dropping(httpx.HTTPTransport):
    """Drops the connection of the `nth` request (its answer never arrives), once."""

    def __init__(self, nth: int) -> None:
        super().__init__()
        self.nth, self.seen = nth, 0

    def handle_request(self, request: httpx.Request) -> httpx.Response:
        self.seen += 1
        if self.seen == self.nth:
            raise httpx.RemoteProtocolError("peer closed connection without sending complete message body")
        return super().handle_request(request)


def test_the_augment_iterator_survives_a_dropped_connection(live_server):
    seeds = [C1, C2, C3]
    with Client(live_server.url, transport=_Dropping(nth=4), backoff=0.01) as c:
        got = [a for a in c.augment_chunks(seeds, 60, seed=9, chunk=10)]  # the 3rd chunk's request is dropped once
    with Client(live_server.url) as c:
        want = c.augment(seeds, 60, seed=9).curves
    assert [a.offset for a in got] == list(range(0, 60, 10))
    np.testing.assert_allclose(np.concatenate([a.curves for a in got]), want, atol=1e-5)


def test_a_full_queue_is_retried_until_it_answers(server_factory, model_dir):
    server = server_factory("--model-dir", str(model_dir), *ONE_SLOT, "--max-queue", "0")  # nothing may queue
    server.wait_ready()
    heavy = {"curves": bspline_curves(256, 161, seed=1).tolist(), "pose": "search", "spacing": "search"}
    busy = threading.Thread(target=lambda: httpx.post(server.url + "/reconstruct", json=heavy, timeout=120))
    statuses: list[int] = []
    with Client(server.url, retries=60, backoff=0.2) as c:
        c.model()
        c._http.event_hooks["response"] = [lambda r: statuses.append(r.status_code)]
        busy.start()
        time.sleep(0.5)  # the one slot is taken and nothing may queue: 503 with Retry-After until it is free
        rec = c.reconstruct([C1])
    busy.join()
    assert statuses[0] == 503 and statuses[-1] == 200 and len(rec.curves) == 1, statuses


def test_a_4xx_is_one_error_with_status_field_and_message_and_is_not_retried(live_server):
    tries: list[int] = []
    with Client(live_server.url, backoff=0.01) as c:
        c.model()
        c._http.event_hooks["response"] = [lambda r: tries.append(r.status_code)]
        with pytest.raises(ApiError) as e:
            c.reconstruct([[[0, 0], [1, float("nan")], [2, 3], [3, 1]]])
    assert e.value.status == 422 and e.value.loc == "curves[0][1][1]" and "number" in e.value.msg
    assert tries == [422]


def test_an_unreachable_server_fails_after_its_retries():
    with Client("http://127.0.0.1:9", retries=2, backoff=0.01) as c, pytest.raises(ApiError, match="after 2 retries"):
        c.model()


def test_the_async_client_answers_as_the_sync_one(live_server):
    async def run() -> tuple:
        async with AsyncClient(live_server.url) as c:
            rec = await c.reconstruct([C1])
            chunks = [a.curves async for a in c.augment_chunks([C1, C2], 12, seed=4, chunk=5)]
            return rec, np.concatenate(chunks)

    rec, streamed = asyncio.run(run())
    with Client(live_server.url) as c:
        np.testing.assert_array_equal(rec.curves, c.reconstruct([C1]).curves)
        np.testing.assert_allclose(streamed, c.augment([C1, C2], 12, seed=4).curves, atol=1e-5)


# ------------------------------------------------------------------ against a stand-in transport

INFO = {"name": "m", "version": "1", "service_version": "0.15.0", "files": {"decoder.onnx": {"sha256": "d" * 64}}}


def _server(answers: list[httpx.Response], seen: list[httpx.Request]):
    """A transport answering GET /model with INFO and every other request with the next of `answers`."""

    def handle(request: httpx.Request) -> httpx.Response:
        if request.url.path == "/model":
            return httpx.Response(200, json=INFO)
        seen.append(request)
        return answers.pop(0)

    return handle


def _busy(status: int = 503) -> httpx.Response:
    return httpx.Response(status, headers={"Retry-After": "0"}, json={"detail": "the queue is full"})


def _fit_answer() -> httpx.Response:
    return httpx.Response(200, json={"fits": []})


@pytest.mark.parametrize("status", [503, 429])
def test_a_busy_answer_is_retried_after_its_retry_after(status):
    seen: list[httpx.Request] = []
    handler = _server([_busy(status), _busy(status), _fit_answer()], seen)
    with Client("http://x", retries=2, backoff=30, transport=httpx.MockTransport(handler)) as c:  # Retry-After: 0
        t = time.monotonic()
        assert c.fit([C1]).fits == []
    assert len(seen) == 3 and time.monotonic() - t < 5
    assert len({r.content for r in seen}) == 1  # the same request each time


def test_busy_past_the_retries_is_one_error_saying_how_many():
    seen: list[httpx.Request] = []
    handler = _server([_busy()] * 3, seen)
    with Client("http://x", retries=2, transport=httpx.MockTransport(handler)) as c:
        with pytest.raises(RetriesExhausted) as e:
            c.fit([C1])
    assert len(seen) == 3 and e.value.status == 503
    assert str(e.value) == "503: the queue is full (after 2 retries)"


@pytest.mark.parametrize("status", [400, 404, 413, 422, 500])
def test_other_refusals_are_not_retried(status):
    seen: list[httpx.Request] = []
    body = {"detail": "n_ctrl: too many", "errors": [{"loc": "n_ctrl", "msg": "too many"}]}
    handler = _server([httpx.Response(status, json=body), _fit_answer()], seen)
    with Client("http://x", retries=3, transport=httpx.MockTransport(handler)) as c:
        with pytest.raises(ApiError) as e:
            c.fit([C1], n_ctrl=99)
    assert len(seen) == 1 and not isinstance(e.value, RetriesExhausted)
    assert (e.value.status, e.value.loc, e.value.msg) == (status, "n_ctrl", "too many")


def test_the_api_key_goes_as_a_bearer_token_and_the_url_loses_its_slash():
    seen: list[httpx.Request] = []
    handler = _server([_fit_answer()], seen)
    with Client("http://x/", api_key="s3cret", transport=httpx.MockTransport(handler)) as c:
        c.fit([C1])
        assert c.url == "http://x" and c.model_ref().url == "http://x"
    assert seen[0].headers["authorization"] == "Bearer s3cret"


def _npy(n: int) -> httpx.Response:
    buf = io.BytesIO()
    np.save(buf, np.full((n, 5, 2), n, np.float32))
    return httpx.Response(200, content=buf.getvalue(), headers={"content-type": "application/x-npy"})


def test_augment_chunks_ask_for_each_chunk_from_its_offset_with_one_seed():
    seen: list[httpx.Request] = []
    handler = _server([_npy(4), _npy(4), _npy(2)], seen)
    with Client("http://x", transport=httpx.MockTransport(handler)) as c:
        got = list(c.augment_chunks([C1, C2], 10, chunk=4, offset=3, mode="pair"))
    bodies = [json.loads(r.content) for r in seen]
    assert [(b["count"], b["offset"]) for b in bodies] == [(4, 3), (4, 7), (2, 11)]
    assert {b["format"] for b in bodies} == {"npy"} and {b["mode"] for b in bodies} == {"pair"}
    seeds = {b["seed"] for b in bodies}
    assert len(seeds) == 1 and [a.seed for a in got] == [*seeds] * 3  # drawn once, carried by every chunk
    assert [a.offset for a in got] == [3, 7, 11] and [len(a.curves) for a in got] == [4, 4, 2]
    assert all(a.stacked().dtype == np.float32 for a in got)  # as streamed: no float64 copy of a chunk


def test_a_fresh_seed_is_a_json_safe_integer():
    seeds = {fresh_seed() for _ in range(50)}
    assert len(seeds) == 50 and all(0 <= s < 2**53 for s in seeds)


def test_the_async_client_retries_as_the_sync_one():
    seen: list[httpx.Request] = []
    handler = _server([_busy(), _fit_answer()], seen)

    async def run() -> list:
        async with AsyncClient("http://x", retries=1, transport=httpx.MockTransport(handler)) as c:
            return (await c.fit([C1])).fits

    assert asyncio.run(run()) == [] and len(seen) == 2
