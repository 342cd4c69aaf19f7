"""What every model route shares (service.deps): the bounded, timed run in a worker thread, caused for real against real
servers (a request over the time limit, more work than the queue takes, a client that disconnects), the checks of what
a request combines (weights, refine work, spline output), and what /model reports of the execution."""

from __future__ import annotations

import concurrent.futures as cf
import time

import httpx
import numpy as np
import pytest
from fastapi.testclient import TestClient

from curve_vae.service.app import create_app
from curve_vae.service.settings import Settings
from tests.helpers import ONE_SLOT

CURVE = [[0, 0], [1, 2], [2.5, 3.2], [4, 3.5], [5.5, 3], [7, 1.5], [8, 0]]


def heavy(curves) -> dict:
    """A request that keeps one inference slot busy for a while: 256 curves of 161 points."""
    return {"curves": curves(256, 161).tolist(), "n_points": 400}


def test_a_request_over_the_time_limit_is_a_504(server_factory, model_dir, curves):
    server = server_factory("--model-dir", str(model_dir), "--providers", "cpu", "--request-timeout", "0.02")
    server.wait_ready()
    r = httpx.post(server.url + "/reconstruct", json=heavy(curves), timeout=60)
    assert r.status_code == 504
    assert r.json()["detail"].startswith("the request took longer than 0.02 s (CURVE_VAE_REQUEST_TIMEOUT)")
    assert httpx.get(server.url + "/health").status_code == 200
    assert httpx.post(server.url + "/fit", json={"curves": [CURVE], "n_ctrl": 4}).status_code == 200  # still serving


def test_more_work_than_the_queue_takes_is_a_503_with_retry_after(server_factory, model_dir, curves):
    server = server_factory("--model-dir", str(model_dir), *ONE_SLOT, "--max-queue", "1")
    server.wait_ready()
    body = heavy(curves)
    with httpx.Client(timeout=120) as http, cf.ThreadPoolExecutor(8) as pool:
        answers = list(pool.map(lambda _: http.post(server.url + "/reconstruct", json=body), range(8)))
    codes = sorted(a.status_code for a in answers)
    assert set(codes) == {200, 503} and codes.count(200) >= 2, codes  # one running, one queued, the rest refused
    busy = next(a for a in answers if a.status_code == 503)
    assert busy.headers["retry-after"] == "1" and busy.json()["detail"].startswith("busy: ")
    assert httpx.post(server.url + "/reconstruct", json={"curves": [CURVE]}).status_code == 200  # and it recovers


def _cpu(server) -> float:
    return sum(server.cpu_seconds().values())


def test_a_request_whose_client_disconnects_stops_and_frees_its_slot(server_factory, model_dir, curves):
    """The client gives up mid-request: the server stops at its next graph run or curve, its one inference slot is
    free for the next request at once, and it goes idle instead of computing the abandoned answer to the end."""
    # one slot: the next request finds it free only if the first stopped
    server = server_factory("--model-dir", str(model_dir), *ONE_SLOT, "--batch-size", "8")
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


def test_a_model_without_a_head_refuses_splines_and_says_why(raw_model_dir, raw_runtime):
    with TestClient(create_app(Settings(model_dir=raw_model_dir), runtime=raw_runtime)) as client:
        assert client.get("/model").json()["spline"] is None
        r = client.post("/reconstruct", json={"curves": [CURVE], "output": "bspline"})
        assert r.status_code == 422
        assert r.json()["detail"].startswith('output: "bspline" needs a model with a B-spline head')
        assert client.post("/reconstruct", json={"curves": [CURVE]}).status_code == 200


@pytest.mark.parametrize(
    ("weights", "status"),
    [
        pytest.param([[0.3, 0.7 + 9e-7]], 200, id="sum-off-by-9e-7"),
        pytest.param([[0.3, 0.7 - 9e-7]], 200, id="sum-short-by-9e-7"),
        pytest.param([[0.3, 0.7 + 2e-6]], 422, id="sum-off-by-2e-6"),
        pytest.param([[1.0, 0.0], [0.5, 0.5 - 2e-6]], 422, id="second-row-off"),
    ],
)
def test_weight_rows_must_sum_to_one_within_a_millionth(client, weights, status):
    r = client.post("/interpolate", json={"curves": [CURVE, CURVE[::-1]], "weights": weights})
    assert r.status_code == status, r.text
    if status == 422:
        row = len(weights) - 1
        total = f"{sum(weights[-1]):.9g}"
        assert r.json()["detail"] == f"weights[{row}]: weights must sum to 1, got {total}"


@pytest.mark.parametrize(
    ("limit", "status"),
    [pytest.param(774, 200, id="work-at-the-limit"), pytest.param(773, 422, id="one-unit-over")],
)
def test_the_refine_work_limit_is_inclusive(make_client, limit, status):
    """One step and the default look on two curves of 7 points: 1 × (14 + 2 × 300) + 1 × 2 × 80 = 774 units."""
    client = make_client(max_refine_work=limit)
    for path, extra in (("/reconstruct", {}), ("/augment", {"count": 1, "seed": 1})):
        r = client.post(path, json={"curves": [CURVE, CURVE[::-1]], "refine": 1, **extra})
        assert r.status_code == status, (path, r.text)
        if status == 422:
            assert r.json()["detail"].startswith(
                "refine: refine 1 and looks 1 on 2 curves of 14 points in all are 774 units of work (refine × "
                "(points + 300 per curve) + looks × 80 per curve); at most 773 (CURVE_VAE_MAX_REFINE_WORK)"
            )


def test_model_reports_the_inference_threads_and_no_micro_batching(make_client):
    execution = make_client(inference_concurrency=3).get("/model").json()["execution"]
    assert execution["inference_threads"] == 3 and execution["micro_batch"] is None


def test_the_switch_interval_is_the_settings_while_the_app_serves_and_the_processs_own_after(model_dir, runtime):
    import sys

    from fastapi.testclient import TestClient

    from curve_vae.service.app import create_app
    from curve_vae.service.settings import Settings

    before = sys.getswitchinterval()
    with TestClient(create_app(Settings(model_dir=model_dir, gil_switch_ms=3.5), runtime=runtime)) as client:
        assert client.get("/model").json()["execution"]["gil_switch_ms"] == 3.5
        assert sys.getswitchinterval() == pytest.approx(0.0035)
    assert sys.getswitchinterval() == before


def test_model_reports_micro_batching_when_on_and_answers_the_same(make_client, runtime):
    client = make_client(
        share_runtime=False,
        providers="cpu",
        micro_batch=True,
        micro_batch_rows=8,
        micro_batch_wait_ms=1.5,
        inference_concurrency=2,
        cache_bytes=0,
    )
    execution = client.get("/model").json()["execution"]
    assert execution["micro_batch"] == {"rows": 8, "wait_ms": 1.5} and execution["inference_threads"] == 2
    z = np.random.default_rng(2).normal(size=(3, 32))
    r = client.post("/decode", json={"latents": z.tolist()})
    np.testing.assert_allclose(r.json()["curves"], runtime.decode(z).curves, rtol=1e-6, atol=1e-9)
