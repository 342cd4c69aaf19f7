"""bench.graph_ops: onnxruntime's per-node profile of the shipped graphs, read back, and the arithmetic its rates
come from, so the table BENCHMARKS quotes does not rot. Times mean nothing here (the suite shares the CPU)."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
pytestmark = pytest.mark.skipif(not (ROOT / "models" / "manifest.json").is_file(), reason="no shipped model")


def test_every_node_of_a_run_is_timed_with_its_shapes():
    from bench.graph_ops import flops, profile

    r = profile(ROOT / "models" / "encoder.onnx", batch=2, runs=2)
    assert r["us"] == pytest.approx(sum(n["us"] for n in r["nodes"].values())) and r["us"] > 0
    convs = [n for n in r["nodes"].values() if n["op"] in ("Conv", "FusedConv")]
    assert convs and all(n["inputs"][0][0] == 2 for n in convs)  # the batch as asked
    for n in convs:  # output positions × weights a position, two operations each
        (b, c_out, length), (_, c_in, k) = n["outputs"][0], n["weights"]
        assert flops(n) == 2 * b * c_out * length * c_in * k


def test_a_transposed_convolution_spreads_each_input_value_over_its_kernels():
    from bench.graph_ops import flops, profile

    r = profile(ROOT / "models" / "decoder.onnx", batch=2, runs=1)
    transposed = [n for n in r["nodes"].values() if n["op"] == "ConvTranspose"]
    assert transposed and all(n["weights"] for n in transposed)  # read from the graph: the profile leaves them out
    for n in transposed:
        (b, c_in, length), (_, c_out, k) = n["inputs"][0], n["weights"]
        assert flops(n) == 2 * b * c_in * length * c_out * k


def test_a_matrix_product_counts_its_inner_dimension_and_other_nodes_nothing():
    from bench.graph_ops import flops

    assert flops({"op": "Gemm", "inputs": [[4, 32], [32, 96]], "outputs": [[4, 96]]}) == 2 * 4 * 96 * 32
    assert flops({"op": "Relu", "inputs": [[4, 96]], "outputs": [[4, 96]]}) == 0


def test_the_table_names_every_shipped_graph():
    done = subprocess.run(
        [sys.executable, "-m", "bench.graph_ops", "--batch", "2", "--runs", "2", "--top", "1", "--curves", "4"],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert done.returncode == 0, done.stderr
    for graph in ("encoder", "decoder", "ranker", "spacer"):
        assert f"| {graph} |" in done.stdout and f"- {graph} " in done.stdout
    assert "A default request of 4 paper curves runs, a curve: encoder " in done.stdout


def test_a_default_request_reads_each_curve_once_or_twice_ranking_every_candidate():
    """The rows counted at onnxruntime's door: one guess a curve, one or two encodings and as many decodings, the
    ranker over every candidate (more than the two read)."""
    from bench.graph_ops import rows_a_curve

    rows = rows_a_curve(ROOT / "models", curves=6)
    assert rows["spacer"] == 1.0 and 1.0 <= rows["encoder"] <= 2.0 and rows["decoder"] == rows["encoder"]
    assert rows["ranker"] > 2.0
