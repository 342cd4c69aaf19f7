"""The serving benchmark's smoke run: one second of wrk against the real server, so bench/serve.py does not rot.

The numbers mean nothing here (the test suite shares the CPU); the run must complete with every answer a 200.
"""

from __future__ import annotations

import json
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

pytestmark = pytest.mark.integration

ROOT = Path(__file__).resolve().parents[2]


@pytest.mark.skipif(
    shutil.which("wrk") is None, reason="wrk is not installed (.ci/run installs it: apt-get install wrk)"
)
@pytest.mark.skipif(not (ROOT / "models" / "manifest.json").is_file(), reason="no shipped model")
def test_the_benchmark_runs_for_a_second(tmp_path):
    out = tmp_path / "bench.json"
    cmd = [sys.executable, "-m", "bench.serve", "--seconds", "1", "--runs", "B", "B_npy", "--json", str(out)]
    done = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True, timeout=180)
    assert done.returncode == 0, done.stderr
    report = json.loads(out.read_text())
    assert report["inprocess"]["ceiling"] > 0
    for run in ("B", "B_npy"):
        assert report[run]["requests"] > 0 and report[run]["non_2xx"] == 0 and report[run]["errors"] == 0
        assert report[run]["server_cpu_ms_per_request"] > 0
    assert "| **B: /reconstruct, 1 curve, the default request**, 16 connections |" in done.stdout


@pytest.mark.skipif(shutil.which("wrk") is None, reason="wrk is not installed")
@pytest.mark.skipif(not (ROOT / "models" / "manifest.json").is_file(), reason="no shipped model")
def test_a_sweep_starts_each_server_with_its_flags():
    from bench.sweep import sweep

    (row,) = sweep(["--workers 1 --gil-switch-ms 3"], seconds=1, with_a=False, model_dir=ROOT / "models")
    assert row["execution"]["gil_switch_ms"] == 3.0  # read back from the server it measured
    assert row["B"]["requests"] > 0 and row["B"]["non_2xx"] == 0 and row["B"]["errors"] == 0
    assert row["B"]["requests_a_batch"] >= 1  # read from the worker's /metrics
