"""Faults caused for real against real servers: SIGTERM in flight, a request over the time limit, more work than the
queue takes, a streamed .npy that fails midway."""

from __future__ import annotations

import concurrent.futures as cf
import signal
import threading
import time

import httpx
import pytest
import uvicorn

from curve_vae.inference.runtime import CurveRuntime
from curve_vae.service.app import create_app
from curve_vae.service.settings import Settings

CURVE = [[0, 0], [1, 2], [2.5, 3.2], [4, 3.5], [5.5, 3], [7, 1.5], [8, 0]]


def heavy(curves) -> dict:
    """A request that keeps one inference slot busy for a while: 256 curves of 161 points."""
    return {"curves": curves(256, 161).tolist(), "n_points": 400}


def test_sigterm_lets_requests_in_flight_finish_then_exits_0(server_factory, model_dir):
    server = server_factory("--model-dir", str(model_dir), "--providers", "cpu")
    server.wait_ready()
    body = {"curves": [CURVE, CURVE[::-1]], "count": 10_000, "format": "npy", "seed": 1, "n_points": 161}
    expected = 128 + 10_000 * 161 * 2 * 4
    with httpx.Client(timeout=120) as http, cf.ThreadPoolExecutor(1) as pool:
        started = threading.Event()

        def download() -> int:
            with http.stream("POST", server.url + "/augment", json=body) as r:
                size = 0
                for chunk in r.iter_bytes():
                    started.set()
                    size += len(chunk)
                return size

        future = pool.submit(download)
        assert started.wait(30)
        server.proc.send_signal(signal.SIGTERM)  # mid-stream
        assert future.result() == expected  # the whole file arrived
    assert server.proc.wait(timeout=60) == 0
    assert "Traceback" not in server.proc.stdout.read()  # type: ignore[union-attr]


def test_a_request_over_the_time_limit_is_a_504(server_factory, model_dir, curves):
    server = server_factory("--model-dir", str(model_dir), "--providers", "cpu", "--request-timeout", "0.02")
    server.wait_ready()
    r = httpx.post(server.url + "/reconstruct", json=heavy(curves), timeout=60)
    assert r.status_code == 504
    assert r.json()["detail"].startswith("the request took longer than 0.02 s (CURVE_VAE_REQUEST_TIMEOUT)")
    assert httpx.get(server.url + "/health").status_code == 200
    assert httpx.post(server.url + "/fit", json={"curves": [CURVE], "n_ctrl": 4}).status_code == 200  # still serving


def test_more_work_than_the_queue_takes_is_a_503_with_retry_after(server_factory, model_dir, curves):
    server = server_factory(
        "--model-dir", str(model_dir), "--providers", "cpu", "--inference-concurrency", "1", "--max-queue", "1"
    )
    server.wait_ready()
    body = heavy(curves)
    with httpx.Client(timeout=120) as http, cf.ThreadPoolExecutor(8) as pool:
        answers = list(pool.map(lambda _: http.post(server.url + "/reconstruct", json=body), range(8)))
    codes = sorted(a.status_code for a in answers)
    assert set(codes) == {200, 503} and codes.count(200) >= 2, codes  # one running, one queued, the rest refused
    busy = next(a for a in answers if a.status_code == 503)
    assert busy.headers["retry-after"] == "1" and busy.json()["detail"].startswith("busy: ")
    assert httpx.post(server.url + "/reconstruct", json={"curves": [CURVE]}).status_code == 200  # and it recovers


def test_a_stream_that_fails_midway_is_visibly_short(model_dir, monkeypatch):
    """The .npy answer carries its Content-Length: a failure after the first chunk ends the connection early, and
    the client sees an incomplete body, never a silently short file."""
    runtime = CurveRuntime.load(model_dir, providers="cpu", intra_op_threads=1)
    real, calls = runtime.augment, []

    def failing(*args, **kwargs):
        calls.append(1)
        if len(calls) == 3:
            raise RuntimeError("the decoder broke down")
        return real(*args, **kwargs)

    monkeypatch.setattr(runtime, "augment", failing)
    config = uvicorn.Config(create_app(Settings(model_dir=model_dir), runtime=runtime), port=0, log_level="critical")
    server = uvicorn.Server(config)
    thread = threading.Thread(target=server.run, daemon=True)
    thread.start()
    try:
        deadline = time.monotonic() + 30
        while not server.started:
            assert time.monotonic() < deadline
            time.sleep(0.05)
        port = server.servers[0].sockets[0].getsockname()[1]
        body = {"curves": [CURVE, CURVE[::-1]], "count": 1000, "format": "npy", "seed": 1}
        with pytest.raises(httpx.RemoteProtocolError, match="incomplete|closed"):
            with httpx.stream("POST", f"http://127.0.0.1:{port}/augment", json=body, timeout=30) as r:
                assert r.status_code == 200 and int(r.headers["content-length"]) == 128 + 1000 * 7 * 2 * 4
                r.read()
    finally:
        server.should_exit = True
        thread.join(timeout=30)
    assert len(calls) == 3


def _cpu(server) -> float:
    return sum(server.cpu_seconds().values())


def test_a_request_whose_client_disconnects_stops_and_frees_its_slot(server_factory, model_dir, curves):
    """The client gives up mid-request: the server stops at its next graph run or curve, its one inference slot is
    free for the next request at once, and it goes idle instead of computing the abandoned answer to the end."""
    server = server_factory(
        "--model-dir", str(model_dir), "--providers", "cpu", "--inference-concurrency", "1", "--batch-size", "8"
    )
    server.wait_ready()
    body = {**heavy(curves), "pose": "search", "spacing": "search"}  # seconds of work on one slot
    start = _cpu(server)
    with pytest.raises(httpx.ReadTimeout):
        httpx.post(server.url + "/reconstruct", json=body, timeout=0.5)  # gives up and closes the connection
    time.sleep(0.5)  # the poll notices, the next checkpoint stops the thread
    idle = _cpu(server)
    time.sleep(1.0)
    assert _cpu(server) - idle < 0.25, "the server kept computing the abandoned request"
    t = time.perf_counter()
    assert httpx.post(server.url + "/reconstruct", json={"curves": [CURVE]}, timeout=10).status_code == 200
    assert time.perf_counter() - t < 2.0  # the slot was free: no waiting behind the abandoned request
    assert idle - start < 3.0  # stopped well before the whole request's work
    metrics = httpx.get(server.url + "/metrics").text
    assert 'curve_vae_inference_cancelled_total{route="/reconstruct"} 1.0' in metrics
