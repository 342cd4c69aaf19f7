"""geometry.validity: which answers cross themselves, and the local refit that uncrosses a B-spline answer."""

from __future__ import annotations

import numpy as np
import pytest

from curve_vae.geometry import self_intersects
from curve_vae.geometry.bspline import basis_and_slope, fit_bspline
from curve_vae.geometry.validity import crosses, crossing_segments, new_crossings, untangled

LOOP = np.array([[0.0, 0.0], [2.0, 0.0], [2.0, 1.0], [1.0, -1.0]])  # its last segment crosses its first
SQUARE = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0], [0.0, 0.0]])  # closed: meets itself at the join
STEP = np.array([[0.0, 0.0], [1.0, 0.0], [2.0, 0.5], [3.0, 0.5], [4.0, 1.0]])


def test_crossings_are_found_for_a_ragged_batch_and_a_loop_may_close():
    assert crosses([LOOP, SQUARE, STEP]).tolist() == [True, False, False]
    assert crosses([]).shape == (0,)
    np.testing.assert_array_equal(crosses([LOOP, SQUARE, STEP]), [self_intersects(c) for c in (LOOP, SQUARE, STEP)])
    assert crossing_segments(LOOP).tolist() == [[0, 2]]
    assert crossing_segments(SQUARE).tolist() == []  # its first and last segments meet at the join only
    touching = np.array([[0.0, 0.0], [2.0, 0.0], [2.0, 1.0], [1.0, 0.0]])  # touches itself: not simple either
    assert crosses([touching]).tolist() == [True]


def test_new_crossings_are_those_whose_input_does_not_cross():
    assert new_crossings([STEP, LOOP, STEP], [LOOP, LOOP, STEP]).tolist() == [True, False, False]


def _thin_wedge(n: int = 121, *, closed: bool) -> np.ndarray:
    """An airfoil-like loop: from a sharp trailing edge over the top and back underneath, a few thousandths thick
    near the edge."""
    beta = np.linspace(0.0, np.pi, (n + 1) // 2)
    x = (1 - np.cos(beta)) / 2
    t = 0.08 * (0.2969 * np.sqrt(x) - 0.126 * x - 0.3516 * x**2 + 0.2843 * x**3 - (0.1036 if closed else 0.1015) * x**4)
    upper = np.stack([x, 5 * t], 1)[::-1]
    lower = np.stack([x, -5 * t], 1)[1:]
    out = np.concatenate([upper, lower])
    if closed:
        out[-1] = out[0]  # a closed file's first point repeated, to the bit
    return out


@pytest.mark.parametrize("closed", [True, False], ids=["closed edge", "open edge"])
def test_a_spline_whose_trailing_edge_crosses_is_refitted_there_alone(closed):
    target = _thin_wedge(closed=closed)
    fit = fit_bspline(target, 31)
    ctrl, u = fit.control_points.copy(), fit.params
    if closed:
        ctrl[0] = ctrl[-1] = (ctrl[0] + ctrl[-1]) / 2
    # the edge's two sides swapped: the first and last inner control points pushed across each other
    ctrl[1, 1] -= 0.02
    ctrl[-2, 1] += 0.02
    basis = basis_and_slope(u, len(ctrl))[0]
    assert self_intersects(basis @ ctrl) and not self_intersects(target)
    before = np.sqrt(((basis @ ctrl - target) ** 2).sum(1).mean())

    fixed, ok = untangled(ctrl, u, target)

    answer = basis @ fixed
    assert ok and not self_intersects(answer)
    assert np.sqrt(((answer - target) ** 2).sum(1).mean()) < before  # never farther: a least-squares refit
    moved = np.flatnonzero(np.abs(fixed - ctrl).max(axis=1) > 0)
    assert moved.min() == 1 and moved.max() == len(ctrl) - 2  # the edge's control points…
    assert len(moved) <= 12  # …and nothing far from it
    np.testing.assert_array_equal(fixed[[0, -1]], ctrl[[0, -1]])  # the ends held: a loop stays a loop


def test_a_spline_that_does_not_cross_comes_back_unchanged():
    target = _thin_wedge(closed=True)
    fit = fit_bspline(target, 31)
    fixed, ok = untangled(fit.control_points, fit.params, target)
    assert ok and np.array_equal(fixed, fit.control_points)
