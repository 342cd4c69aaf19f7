"""bench.profile_one's smoke run: a few single-curve requests profiled (one-pass and default), every stage found, so
the script that BENCHMARKS' profile tables come from does not rot. The numbers mean nothing here (the suite shares
the CPU)."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


@pytest.mark.skipif(not (ROOT / "models" / "manifest.json").is_file(), reason="no shipped model")
@pytest.mark.parametrize("reading", ["one-pass", "default"])
def test_the_profile_names_each_stage_and_they_add_up(reading):
    from bench.profile_one import READINGS, measure

    stages = READINGS[reading][1]
    shares = measure(ROOT / "models", requests=5, reading=reading)
    assert set(stages) <= set(shares) and shares["wall_ms_per_request"] > shares["graphs_ms_per_request"] > 0
    for stage in stages:  # every stage's functions ran: a renamed function would show as 0
        assert 0 < shares[stage] < 1, stage
    parts = {k: v for k, v in shares.items() if not k.endswith("_ms_per_request")}
    inner = {k for k in parts if k.startswith("of which")}  # a share of the stage above it, not counted twice
    assert sum(v for k, v in parts.items() if k not in inner) == pytest.approx(1.0)
    assert all(0 < parts[k] < 1 for k in inner)


def test_the_markdown_table_prints():
    done = subprocess.run(
        [sys.executable, "-m", "bench.profile_one", "--requests", "3", "--markdown"],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert done.returncode == 0, done.stderr
    assert "| placement on the spline |" in done.stdout and "wall time per request" in done.stdout
    assert "| its two graphs alone, the same curve in the model plane |" in done.stdout
