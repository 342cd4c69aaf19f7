"""Concurrent /reconstruct and /encode requests read together (service.deps, the coalescer): each answered its own, as
if alone; a bad one fails alone; off with CURVE_VAE_COALESCE_CURVES=0; the batches in /metrics; on a real server too."""

from __future__ import annotations

import httpx
import numpy as np

from tests.helpers import together


def _coalesced(metrics: str) -> tuple[float, float]:
    """(batches, requests) of curve_vae_coalesced_requests in a /metrics text."""
    values = {}
    for line in metrics.splitlines():
        for part in ("count", "sum"):
            if line.startswith(f"curve_vae_coalesced_requests_{part} "):
                values[part] = float(line.split()[1])
    return values["count"], values["sum"]


def test_concurrent_requests_each_get_their_own_answer(make_client, curves):
    coalescing, alone = make_client(), make_client(coalesce_curves=0)
    bodies = [{"curves": curves(1 + i % 3, 40 + i, seed=i).tolist()} for i in range(16)]
    answers = together(lambda body: coalescing.post("/reconstruct", json=body), bodies)
    for body, answer in zip(bodies, answers):
        assert answer.status_code == 200, answer.text
        own = alone.post("/reconstruct", json=body).json()
        for got, want in zip(answer.json()["curves"], own["curves"], strict=True):
            np.testing.assert_allclose(got, want, rtol=1e-4, atol=1e-4)
        np.testing.assert_allclose(answer.json()["mse"], own["mse"], rtol=1e-3)
    batches, requests = _coalesced(coalescing.get("/metrics").text)
    assert requests == 16 and batches < 16  # sixteen at once on two inference threads: some read together
    assert _coalesced(alone.get("/metrics").text) == (0, 0)  # off: nothing coalesced
    large = coalescing.post("/reconstruct", json={"curves": curves(17, 40).tolist()})  # over half a batch: alone
    assert large.status_code == 200 and _coalesced(coalescing.get("/metrics").text)[1] == 16


def test_model_reports_coalescing(make_client):
    assert make_client(coalesce_curves=16).get("/model").json()["execution"]["coalesce"] == {
        "curves": 16,
        "readers": 1,  # the tests' app: one worker a CPU
        "hold_ms": 5.0,
    }
    assert make_client(coalesce_curves=0).get("/model").json()["execution"]["coalesce"] is None


def test_concurrent_encodings_too(make_client, curves):
    coalescing, alone = make_client(), make_client(coalesce_curves=0)
    bodies = [{"curves": curves(2, 50, seed=i).tolist()} for i in range(8)]
    answers = together(lambda body: coalescing.post("/encode", json=body), bodies)
    for body, answer in zip(bodies, answers):
        assert answer.status_code == 200, answer.text
        np.testing.assert_allclose(answer.json()["mean"], alone.post("/encode", json=body).json()["mean"], atol=1e-4)
    assert _coalesced(coalescing.get("/metrics").text)[1] == 8


def test_a_bad_request_among_others_fails_alone(make_client, curves):
    client = make_client()
    good = {"curves": curves(1, 40).tolist()}
    bad = {"curves": [*curves(1, 40).tolist(), [[1.0, 1.0]] * 40]}  # its second curve: one point forty times
    answers = together(lambda body: client.post("/reconstruct", json=body), [good, good, bad, good, good, good])
    assert [a.status_code for a in answers] == [200, 200, 422, 200, 200, 200]
    # its own second curve, wherever it sat in a batch
    assert answers[2].json()["errors"][0]["loc"] == "curves[1]" and "coincide" in answers[2].json()["detail"]


def test_a_real_server_reads_concurrent_requests_together(server_factory, model_dir, curves):
    server = server_factory("--model-dir", str(model_dir), "--providers", "cpu")
    server.wait_ready()
    bodies = [{"curves": curves(1, 60, seed=i).tolist()} for i in range(24)]
    with httpx.Client(timeout=60) as http:
        answers = together(lambda body: http.post(f"{server.url}/reconstruct", json=body), bodies)
        for body, answer in zip(bodies, answers):
            assert answer.status_code == 200, answer.text
            own = http.post(f"{server.url}/reconstruct", json=body).json()  # alone: nobody else is asking now
            np.testing.assert_allclose(answer.json()["curves"], own["curves"], rtol=1e-4, atol=1e-4)
        batches, requests = _coalesced(http.get(f"{server.url}/metrics").text)
    assert requests == 48 and batches < 48
    assert server.stop() == 0
