"""bench.threads: one thread's and two threads' rates with the cores they kept busy and the CPU a request cost, so
the figures BENCHMARKS quotes come from a script that still runs. Times mean nothing here (the suite shares the
CPU); what is checked is what the figures are made of."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
pytestmark = pytest.mark.skipif(not (ROOT / "models" / "manifest.json").is_file(), reason="no shipped model")


def test_the_rate_and_the_cpu_are_counted_over_the_same_requests(shipped_runtime):
    from bench.ceiling import posted
    from bench.threads import READINGS, measure

    requests = [[c] for c in posted(4, seed=3)]
    m = measure(shipped_runtime, requests, READINGS["one-pass"], 2, 0.5)
    assert m["rate"] > 0 and 0 < m["cores_busy"] <= 2.5  # two threads, a little of the runtime's own beside them
    # cores busy ÷ requests a second is the CPU a request cost
    assert m["cpu_ms_per_request"] == pytest.approx(1e3 * m["cores_busy"] / m["rate"], rel=0.05)


def test_the_command_prints_both_rates_and_what_each_cost():
    cmd = [sys.executable, "-m", "bench.threads", "--reading", "one-pass", "--seconds", "0.5"]
    done = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    lines = done.stdout.strip().splitlines()
    assert re.fullmatch(
        r"one-pass reading, requests a second: one thread [\d.]+, two threads [\d.]+ \([\d.]+×\)", lines[0]
    )
    for line, name in zip(lines[1:], ("one thread", "two threads")):
        assert re.fullmatch(rf"  {name}: [\d.]+ cores busy, [\d.]+ ms of CPU a request", line), line
