"""Micro-batching: concurrent requests' graph runs gathered into one run, each caller getting its own rows back;
a bad item fails alone; a client that goes away disturbs no one; batch sizes and queue waits in /metrics."""

from __future__ import annotations

import concurrent.futures as cf

import httpx
import numpy as np
import pytest
from prometheus_client import CollectorRegistry

from curve_vae.inference.model.batching import GraphBatcher
from tests.helpers import together

BATCHING = {"micro_batch": True, "micro_batch_rows": 16, "micro_batch_wait_ms": 30.0}


@pytest.fixture
def registry():
    return CollectorRegistry()


@pytest.fixture
def batcher(runtime, registry):
    b = GraphBatcher(
        runtime.graphs.pool,
        {"encoder": "curves", "decoder": "latent"},
        max_rows=16,
        max_wait=0.05,
        runners=1,
        registry=registry,
    )
    yield b
    b.close()


def test_each_caller_gets_its_own_rows(batcher, registry, runtime, curves):
    inputs = [curves(k, seed=k).astype(np.float32) for k in (1, 2, 3, 1, 2, 1)]  # 10 rows, different counts
    got = together(lambda x: batcher.run("encoder", x, ["mean", "log_var"]), inputs)
    for x, (mean, log_var) in zip(inputs, got):
        alone = runtime.graphs.encoder.run(["mean", "log_var"], {"curves": x})
        np.testing.assert_allclose(mean, alone[0], rtol=1e-4, atol=1e-4)
        np.testing.assert_allclose(log_var, alone[1], rtol=1e-4, atol=1e-4)
    graph = {"graph": "encoder"}
    assert registry.get_sample_value("curve_vae_microbatch_rows_sum", graph) == 10
    assert registry.get_sample_value("curve_vae_microbatch_rows_count", graph) < 6  # fewer runs than callers


def test_a_bad_item_fails_alone(batcher, curves):
    good = [curves(1, seed=k).astype(np.float32) for k in range(4)]
    bad = np.zeros((1, 100, 2), np.float32)  # the encoder takes 161 points
    got = together(lambda x: batcher.run("encoder", x, ["mean"]), [*good[:2], bad, *good[2:]])
    assert isinstance(got[2], Exception) and "100" in str(got[2])
    assert all(isinstance(r, list) and r[0].shape == (1, 32) for i, r in enumerate(got) if i != 2)


def test_requests_are_routed_to_their_callers_under_concurrency(make_client, client, curves):
    batched = make_client(**BATCHING)
    assert batched.get("/model").json()["execution"]["micro_batch"] == {"rows": 16, "wait_ms": 30.0}
    bodies = [
        {"curves": curves(1 + i % 3, 40, seed=i).tolist(), "pose": "as_is" if i % 2 else "auto"} for i in range(12)
    ]
    answers = together(lambda body: batched.post("/reconstruct", json=body), bodies)
    for body, answer in zip(bodies, answers):
        assert answer.status_code == 200, answer.text
        alone = client.post("/reconstruct", json=body).json()  # the same app without batching
        np.testing.assert_allclose(answer.json()["curves"], alone["curves"], atol=1e-3)

    def encoder_runs() -> float:
        metrics = batched.get("/metrics").text
        assert 'curve_vae_microbatch_rows_count{graph="encoder"}' in metrics
        assert 'curve_vae_microbatch_queue_seconds_count{graph="decoder"}' in metrics
        return float(metrics.split('curve_vae_microbatch_rows_count{graph="encoder"} ')[1].split()[0])

    # twelve quick requests at once (one encoder run each alone; the ones above spend a varying time on their
    # natural fits before they reach the encoder, so whether they meet in its 30 ms window depends on the load)
    before = encoder_runs()
    quick = [{"curves": curves(1, 40, seed=i).tolist(), "pose": "as_is", "spacing": "parameter"} for i in range(12)]
    assert all(a.status_code == 200 for a in together(lambda body: batched.post("/reconstruct", json=body), quick))
    assert encoder_runs() - before < 12  # the twelve requests' encoder runs were gathered into fewer runs


def test_one_bad_request_fails_alone(make_client, curves):
    batched = make_client(**BATCHING)
    good = {"curves": curves(1, 40).tolist(), "pose": "as_is"}
    bad = {"curves": (curves(1, 40) * 1e300).tolist(), "frame": "model"}  # beyond float32: a 422 of its own
    answers = together(lambda body: batched.post("/reconstruct", json=body), [good, good, bad, good])
    assert [a.status_code for a in answers] == [200, 200, 422, 200]


def test_a_client_that_goes_away_disturbs_no_one(server_factory, model_dir, curves):
    server = server_factory(
        "--model-dir", str(model_dir), "--providers", "cpu", "--micro-batch", "true", "--micro-batch-wait-ms", "50"
    )
    server.wait_ready()
    body = {"curves": curves(1, 40).tolist(), "pose": "as_is"}

    def impatient(_):
        try:
            httpx.post(f"{server.url}/reconstruct", json=body, timeout=0.005)  # gone before the batch has run
        except httpx.TimeoutException:
            return "gone"
        return "answered"

    def patient(_):
        return httpx.post(f"{server.url}/reconstruct", json=body, timeout=30)

    with cf.ThreadPoolExecutor(12) as pool:
        gone = [pool.submit(impatient, i) for i in range(6)]
        stayed = [pool.submit(patient, i) for i in range(6)]
        results = [f.result() for f in stayed]
        assert all(f.result() in ("gone", "answered") for f in gone)
    expected = results[0].json()["curves"]
    assert all(r.status_code == 200 and r.json()["curves"] == expected for r in results)
    after = httpx.post(f"{server.url}/reconstruct", json=body, timeout=30)
    assert after.status_code == 200 and after.json()["curves"] == expected
    assert server.stop() == 0
