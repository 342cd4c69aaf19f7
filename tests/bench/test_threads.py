"""bench.threads: one thread's and two threads' rates with the cores they kept busy and the CPU a request cost, so
the figures BENCHMARKS quotes come from a script that still runs. The figures' meaning is checked on stand-ins whose
answer is known (a request that waits, one that holds the GIL); on the shipped model only the printed form, since
times mean nothing while the suite shares the CPU."""

from __future__ import annotations

import re
import subprocess
import sys
import time
from pathlib import Path

import pytest

from bench.threads import READINGS, measure

ROOT = Path(__file__).resolve().parents[2]


class _Waiting:
    """A request that waits 20 ms and costs no CPU (sleep releases the GIL)."""

    def reconstruct(self, curves, reading):
        time.sleep(0.02)


class _HoldingTheGil:
    """A request that spins 20 ms in Python: the GIL held throughout."""

    def reconstruct(self, curves, reading):
        stop = time.thread_time() + 0.02
        while time.thread_time() < stop:
            pass


def test_requests_that_wait_keep_no_core_busy_and_two_threads_answer_twice_as_many():
    one = measure(_Waiting(), [[None]], READINGS["default"], 1, 0.4)
    two = measure(_Waiting(), [[None]], READINGS["default"], 2, 0.4)
    assert one["cores_busy"] < 0.3 and two["cores_busy"] < 0.3
    assert one["cpu_ms_per_request"] < 5  # of 20 ms a request
    assert two["rate"] > 1.5 * one["rate"]


def test_requests_that_hold_the_gil_keep_at_most_one_core_busy_however_many_threads():
    two = measure(_HoldingTheGil(), [[None]], READINGS["default"], 2, 0.6)
    assert two["cores_busy"] < 1.35  # the second thread waits for the GIL: not two cores
    assert two["cpu_ms_per_request"] >= 15  # each request's 20 ms of CPU, counted


@pytest.mark.skipif(not (ROOT / "models" / "manifest.json").is_file(), reason="no shipped model")
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
