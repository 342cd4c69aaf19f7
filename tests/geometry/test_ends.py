"""geometry.ends: a clamped B-spline's end points moved onto given points, the move fading with its size."""

from __future__ import annotations

import numpy as np

from curve_vae.geometry import evaluate_bspline, fit_bspline
from curve_vae.geometry.ends import fading, greville, pinned_ends


def _arc(n_ctrl: int = 31) -> np.ndarray:
    t = np.linspace(0.0, np.pi, 200)
    return fit_bspline(np.c_[np.cos(t), np.sin(t)] * 50 + 64, n_ctrl).control_points


def test_the_spline_starts_and_ends_exactly_where_asked():
    ctrl = np.stack([_arc(), _arc() + 3.0])
    starts, ends = np.array([[10.0, 60.0], [15.5, 70.25]]), np.array([[118.0, 62.0], [120.0, 66.0]])
    pinned = pinned_ends(ctrl, starts, ends, per_move=8.0)
    for c, s, e in zip(pinned, starts, ends):
        curve = evaluate_bspline(c, np.array([0.0, 1.0]))
        np.testing.assert_array_equal(curve[0], s)
        np.testing.assert_array_equal(curve[1], e)


def test_a_small_move_shifts_the_end_control_point_alone_and_a_large_one_fades_along():
    ctrl = _arc()[None]
    length = np.linalg.norm(np.diff(ctrl[0], axis=0), axis=1).sum()
    small = pinned_ends(ctrl, ctrl[:, 0] + [0.001 * length, 0.0], ctrl[:, -1], per_move=1.0)[0]
    moved = np.flatnonzero(np.abs(small - ctrl[0]).max(axis=1) > 0)
    assert moved.tolist() == [0]
    large = pinned_ends(ctrl, ctrl[:, 0] + [0.05 * length, 0.0], ctrl[:, -1], per_move=8.0)[0]
    shift = np.abs(large - ctrl[0])[:, 0]
    moved = np.flatnonzero(shift > 0)
    assert moved[0] == 0 and 4 <= len(moved) <= 15 and moved.max() < 15  # 8 × 5%: 40% of the way at most
    assert (np.diff(shift[moved]) <= 1e-12).all()  # fading, never growing, along the curve
    np.testing.assert_array_equal(large[15:], ctrl[0, 15:])  # the rest as it was


def test_a_closed_curves_ends_moved_onto_one_point_stay_one():
    ctrl = _arc()[None]
    point = np.array([[64.0, 20.0]])
    pinned = pinned_ends(ctrl, point, point, per_move=8.0)[0]
    np.testing.assert_array_equal(pinned[0], pinned[-1])


def test_the_fade_is_a_smoothstep_of_the_greville_abscissae():
    g = greville(31, 3)
    assert g[0] == 0.0 and g[-1] == 1.0 and (np.diff(g) > 0).all()
    w = fading(g, np.array([0.2]))[0]
    assert w[0] == 1.0 and (w[g >= 0.2] == 0).all() and (np.diff(w) <= 0).all()
