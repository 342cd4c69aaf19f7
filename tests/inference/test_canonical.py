"""A model that reads curves in the canonical pose (its manifest's reading): one encoding and one decoding per
curve, and the same answer for a curve, its reversal, its mirror image and its rotations."""

from __future__ import annotations

import json
import shutil

import numpy as np
import pytest

from curve_vae.inference.reading import Reading
from curve_vae.inference.runtime import CurveRuntime
from tests.helpers import bspline_curves

#: How close the answers for moved copies of a curve come back, relative to its size: float rounding of the moves.
TOLERANCE = 1e-6


@pytest.fixture(scope="module")
def canonical(model_dir, tmp_path_factory) -> CurveRuntime:
    out = tmp_path_factory.mktemp("canonical")
    shutil.copytree(model_dir, out, dirs_exist_ok=True)
    manifest = json.loads((out / "manifest.json").read_text())
    manifest["reading"] = {"pose": "canonical", "spacing": "parameter"}
    manifest["spline"]["placement"] = "closest"
    (out / "manifest.json").write_text(json.dumps(manifest))
    return CurveRuntime.load(out, providers="cpu", intra_op_threads=1, cache_bytes=0)


def _moves(c: np.ndarray) -> dict[str, tuple]:
    a = np.radians(130)
    turn = np.array([[np.cos(a), np.sin(a)], [-np.sin(a), np.cos(a)]])
    return {
        "reversed": (c[::-1], lambda x: x[::-1]),
        "mirrored": (c * [-1.0, 1.0], lambda x: x * [-1.0, 1.0]),
        "rotated": (c @ turn * 2.5 + 40, lambda x: x @ turn * 2.5 + 40),
        "all of them": ((c * [-1.0, 1.0])[::-1] @ turn, lambda x: (x * [-1.0, 1.0])[::-1] @ turn),
    }


def test_the_default_reading_is_one_pass(canonical):
    assert canonical.reading() == Reading(pose="canonical", spacing="parameter")
    rows: dict[str, list[int]] = {"encoder": [], "decoder": []}
    run = canonical.graphs._run_graph
    canonical.graphs._run_graph = lambda s, graph, x, o: rows[graph].append(len(x)) or run(s, graph, x, o)
    try:
        canonical.reconstruct(list(bspline_curves(10, 90, seed=3) * 0.3 - 5))
    finally:
        canonical.graphs._run_graph = run
    assert sum(rows["encoder"]) == 10 and sum(rows["decoder"]) == 10


@pytest.mark.parametrize("move", ["reversed", "mirrored", "rotated", "all of them"])
def test_a_moved_curve_comes_back_as_the_curve_moved(canonical, move):
    for c in [
        *bspline_curves(4, 120, seed=8) * 0.05,
        np.stack([np.linspace(0, 3, 80), np.sin(np.linspace(0, 4, 80))], 1),
    ]:
        moved, how = _moves(c)[move]
        (own,), (back,) = canonical.reconstruct([c]).curves, canonical.reconstruct([moved]).curves
        size = np.ptp(how(c), axis=0).max()
        np.testing.assert_allclose(back, how(own), atol=TOLERANCE * size)
