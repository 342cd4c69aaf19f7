"""Answers keep their inputs' ends (inference.placing): a reconstruction starts and ends where its input does, every
in-between — /interpolate, /augment — at the weighted blend of its inputs' matching ends, a closed curve closes."""

from __future__ import annotations

import numpy as np
import pytest

from curve_vae.geometry import diagonal, simplex_grid
from curve_vae.inference.reading import Reading
from curve_vae.inference.runtime import CurveRuntime
from tests.helpers import bspline_curves
from tests.inference.test_untangling import naca

#: The README's pair: both start at (0, 0).
PAIR = [
    np.array([[0, 0], [1, 2], [2.5, 3.2], [4, 3.5], [5.5, 3], [7, 1.5], [8, 0]], float),
    np.array([[0, 0], [1.5, 0.5], [3, 2], [4, 4], [5, 6.5], [6.5, 8], [8, 8.5]], float),
]


def _at(points: np.ndarray, where: np.ndarray, size: float) -> float:
    """How far a point is from where it should be, as a share of `size`."""
    return float(np.linalg.norm(points - where) / size)


def _ends_at(curve: np.ndarray, ends: np.ndarray, size: float) -> float:
    """How far a curve's two ends are from `ends` (2, 2), in the order they come (an in-between is listed as the input
    it is most like), as a share of `size`."""
    return min(_at(curve[[0, -1]], ends, size), _at(curve[[-1, 0]], ends, size))


def test_the_readmes_pair_shares_its_start_with_every_in_between(shipped_runtime: CurveRuntime):
    weights = simplex_grid(2, 9)
    res = shipped_runtime.interpolate(PAIR, weights)
    size = diagonal(np.concatenate(PAIR))
    for w, curve in zip(weights, res.curves):
        assert _at(curve[0], np.zeros(2), size) < 1e-12
        assert _at(curve[-1], w @ np.array([p[-1] for p in PAIR]), size) < 1e-12
    assert res.valid.all()
    sized = shipped_runtime.interpolate(PAIR, weights, n_points=50).curves  # at another count too
    assert max(_at(c[0], np.zeros(2), size) for c in sized) < 1e-12


@pytest.mark.parametrize("pose", ["learned", "canonical", "search"])
def test_each_answer_starts_and_ends_where_its_input_does(shipped_runtime: CurveRuntime, pose: str):
    curves = [c * 0.7 + [3.0, -2.0] for c in bspline_curves(4, seed=41)] + [
        np.c_[np.linspace(0, 5, 30), np.sin(np.linspace(0, 5, 30))]
    ]
    rec = shipped_runtime.reconstruct(curves, Reading(pose=pose))
    for c, o in zip(curves, rec.curves):
        np.testing.assert_allclose(o[[0, -1]], c[[0, -1]], rtol=0, atol=1e-9 * diagonal(c))
    for c, s in zip(curves, rec.splines):  # the spline returned starts and ends there too
        np.testing.assert_allclose(s.control_points[[0, -1]], c[[0, -1]], rtol=0, atol=1e-9 * diagonal(c))


def test_a_closed_answer_closes_at_its_inputs_closing_point(shipped_runtime: CurveRuntime):
    loops = [naca(0.02, 0.12, 81), naca(0.04, 0.15, 121)]
    rec = shipped_runtime.reconstruct(loops)
    for c, o in zip(loops, rec.curves):
        np.testing.assert_array_equal(o[0], o[-1])
        np.testing.assert_allclose(o[0], c[0], atol=1e-12)
    sweep = shipped_runtime.interpolate(loops, simplex_grid(2, 5)).curves
    for w, o in zip(simplex_grid(2, 5), sweep):
        np.testing.assert_array_equal(o[0], o[-1])
        np.testing.assert_allclose(o[0], w @ np.array([c[0] for c in loops]), atol=1e-12)


def test_ends_match_as_the_set_is_read_a_curve_listed_the_other_way_round_too(shipped_runtime: CurveRuntime):
    """A variation of a curve listed from its other end: the set is read in one pose (geometry.batch.
    shared_pose_frames reads it reversed), so its last point is the one that matches the first curve's first point,
    and every in-between starts at their blend."""
    a = PAIR[0]
    b = (a + [[0, 0], [0, 0.3], [0, 0.5], [0, 0.6], [0, 0.5], [0, 0.3], [0.2, 0.4]])[::-1]  # from (8.2, 0.4)
    weights = simplex_grid(2, 5)
    out = shipped_runtime.interpolate([a, b], weights).curves
    size = diagonal(np.concatenate([a, b]))
    for w, o in zip(weights, out):
        assert _ends_at(o, np.tensordot(w, np.array([a[[0, -1]], b[[-1, 0]]]), axes=1), size) < 1e-12


def test_a_triplets_in_betweens_start_at_the_weighted_blend(shipped_runtime: CurveRuntime):
    curves = [c * 2.0 for c in bspline_curves(3, seed=42)]
    weights = np.array([[0.2, 0.3, 0.5], [1 / 3, 1 / 3, 1 / 3], [0.7, 0.1, 0.2], [1.2, -0.1, -0.1]])
    out = shipped_runtime.interpolate(curves, weights).curves
    frames = shipped_runtime.encode(curves, together=True).frames
    # each input's ends in the set's pose: its first point first, or its last where the pose reverses it; the
    # in-betweens come back in the first curve's order
    ends = np.array(
        [[c[-1], c[0]] if f.reverse != frames[0].reverse else [c[0], c[-1]] for c, f in zip(curves, frames)]
    )
    for w, o in zip(weights, out):
        np.testing.assert_allclose(o[[0, -1]], np.tensordot(w, ends, axes=1), rtol=0, atol=1e-9 * diagonal(o))


def test_augmented_curves_start_and_end_at_their_sources_blended_ends(shipped_runtime: CurveRuntime):
    seeds = [c * 3.0 + 7.0 for c in bspline_curves(5, seed=43)]
    for mode in ("pair", "triplet"):
        plan = shipped_runtime.plan_augment(seeds, seed=3, mode=mode)
        got = shipped_runtime.augment(plan, 0, 12)
        frames = plan.prep.frames
        for curve, src, w in zip(got.curves, got.sources, got.weights):
            lead = frames[src[0]].reverse  # a mix comes back in its anchor's order
            ends = np.array(
                [[seeds[s][-1], seeds[s][0]] if frames[s].reverse != lead else seeds[s][[0, -1]] for s in src]
            )
            np.testing.assert_allclose(
                curve[[0, -1]], np.tensordot(w, ends, axes=1), rtol=0, atol=1e-9 * diagonal(curve)
            )


def test_in_betweens_keep_closeness_and_validity_through_the_service(client):
    body = {"curves": [p.tolist() for p in PAIR], "steps": 5}
    answer = client.post("/interpolate", json=body).json()
    assert all(np.allclose(c[0], [0.0, 0.0], atol=1e-9) for c in answer["curves"])
    assert len(answer["valid"]) == 5
