"""bench/report.py: what a run's breakdown says of B's server CPU, whichever way the numbers fall."""

from __future__ import annotations

import re

from bench.report import _breakdown

B = {
    "onnx_b1_ms": 2.7, "onnx_b128_ms": 277, "reconstruct_default_b1_ms": 4.0, "reconstruct_default_b128_ms": 873,
    "reconstruct_fast_b1_ms": 3.0, "reconstruct_fast_b128_ms": 617, "reconstruct_search_b1_ms": 56.9,
    "parse_validate_b1_ms": 0.09, "parse_validate_b128_ms": 63.7, "render_b1_ms": 0.01, "render_b128_ms": 1.5,
}  # fmt: skip


def _said(server_ms: float) -> str:
    return _breakdown({"inprocess": {"breakdown": B}, "B": {"server_cpu_ms_per_request": server_ms}})[-1]


def test_the_rest_of_bs_server_cpu_is_what_the_runtime_and_json_leave():
    said = _said(9.0)
    assert "Of B's 9.00 ms of server CPU per request, 4.00 are the runtime's work in isolation" in said
    assert "the other 4.91 ms are HTTP" in said


def test_a_server_cpu_below_the_isolated_work_is_said_to_be_unsplit_not_a_negative_rest():
    said = _said(3.5)
    assert re.search(r"-\d", said) is None and "the other" not in said
    assert "B's 3.50 ms of server CPU per request are less than the runtime's work in isolation (4.00 ms)" in said
