"""A start that says what it does: the service accepts connections at once, /health 200 and /ready 503, both saying
"warming up"
while the reading's kernels compile (a first start, an empty numba cache) or load, a request sent meanwhile waits
for the warm-up, and the log says which it did and when it was ready."""

from __future__ import annotations

import json
import time
import urllib.error
import urllib.request

import pytest

from curve_vae.service.live import LiveServer
from tests.helpers import ROOT, SHIPPED

pytestmark = pytest.mark.integration


def _get(url: str) -> tuple[int, dict]:
    try:
        with urllib.request.urlopen(url, timeout=5) as r:
            return r.status, json.loads(r.read())
    except urllib.error.HTTPError as e:
        return e.code, json.loads(e.read())


def _first_answer(url: str, started: float, within: float) -> float:
    """Seconds from `started` until `url` answers at all."""
    while time.monotonic() - started < within:
        try:
            _get(url)
            return time.monotonic() - started
        except OSError:
            time.sleep(0.05)
    raise AssertionError(f"{url} did not answer within {within} s")


def test_a_first_start_answers_at_once_says_it_is_compiling_and_then_is_ready(tmp_path):
    cache = tmp_path / "numba-cache"  # empty: what a new container or pod starts with
    started = time.monotonic()
    env = {"NUMBA_CACHE_DIR": str(cache), "CURVE_VAE_CACHE_BYTES": "0"}
    server = LiveServer("--model-dir", str(SHIPPED), "--providers", "cpu", "--workers", "1", env=env, cwd=ROOT,
                        log_level="info")  # fmt: skip
    try:
        answered = _first_answer(f"{server.url}/health", started, within=30)
        assert answered < 10, answered  # connections from the start: the model opens in ~1-3 s, then warms up apart
        status, body = _get(f"{server.url}/ready")
        assert (status, body["status"]) == (503, "warming up") and "compile" in body["detail"]
        status, body = _get(f"{server.url}/health")  # alive, and says what it does
        assert (status, body["status"]) == (200, "warming up")
        curve = [[0, 0], [1, 2], [2.5, 3.2], [4, 3.5], [5.5, 3], [7, 1.5], [8, 0]]
        request = urllib.request.Request(f"{server.url}/reconstruct", json.dumps({"curves": [curve]}).encode(),
                                         {"Content-Type": "application/json"})  # fmt: skip
        with urllib.request.urlopen(request, timeout=180) as r:  # sent while warming up: waits, then answered
            assert r.status == 200 and len(json.loads(r.read())["curves"][0]) == 7
        server.wait_ready(timeout=180)
    finally:
        server.stop()
    log = server.output()
    assert "warming up: compiling the reading's kernels into" in log and str(cache) in log
    assert "ready after" in log

    again = LiveServer("--model-dir", str(SHIPPED), "--providers", "cpu", "--workers", "1", env=env, cwd=ROOT,
                       log_level="info")  # fmt: skip
    try:
        again.wait_ready(timeout=120)
    finally:
        again.stop()
    assert "warming up: loading the reading's compiled kernels from" in again.output()
