"""geometry.matching: each point of a curve matched to a point of a spline, in order, as close as it can be."""

from __future__ import annotations

import numpy as np
import pytest

from curve_vae.geometry import (
    closest_params,
    evaluate_bspline,
    ordered_closest_params,
    random_control_points,
    sample_bspline,
)


def _splines(count: int, seed: int = 0) -> np.ndarray:
    return random_control_points(np.random.default_rng(seed), count, n_ctrl=31)


def test_points_on_the_spline_are_matched_to_themselves():
    ctrl = _splines(3)
    u = np.sort(np.random.default_rng(1).uniform(0, 1, (3, 50)), axis=1)
    u[:, 0], u[:, -1] = 0.0, 1.0
    pts = [evaluate_bspline(c, p) for c, p in zip(ctrl, u)]
    found, distance = ordered_closest_params(ctrl, pts)
    for f, p in zip(found, u):
        np.testing.assert_allclose(f, p, atol=2e-3)
    assert distance.max() < 1e-6


@pytest.mark.parametrize("lengths", [pytest.param((161, 161), id="equal"), pytest.param((7, 300, 40), id="ragged")])
def test_matches_are_ordered_from_end_to_end_and_no_further_than_the_windowed_search(lengths):
    ctrl = _splines(len(lengths), seed=2)
    rng = np.random.default_rng(3)
    pts = [sample_bspline(c, n) + rng.normal(0, 0.5, (n, 2)) for c, n in zip(ctrl, lengths)]
    found, distance = ordered_closest_params(ctrl, pts)
    for c, p, u, d in zip(ctrl, pts, found, distance):
        assert len(u) == len(p) and u[0] == 0.0 and u[-1] == 1.0 and np.all(np.diff(u) >= 0)
        np.testing.assert_allclose(((evaluate_bspline(c, u) - p) ** 2).sum(), d, rtol=1e-9)
        # the windowed search from the points' own fractions, ends pinned and kept in order as the runtime did
        near = closest_params(c, p, np.linspace(0, 1, len(p)))
        near[0], near[-1] = 0.0, 1.0
        near = np.maximum.accumulate(near)
        assert d <= ((evaluate_bspline(c, near) - p) ** 2).sum() * (1 + 1e-3)


def test_a_curve_that_comes_back_near_itself_is_not_matched_across():
    """An airfoil-like loop: its upper and lower surfaces lie close; the order keeps each point on its own side."""
    t = np.linspace(0, 2 * np.pi, 200)
    loop = np.stack([np.cos(t), 0.05 * np.sin(t)], axis=1)
    from curve_vae.geometry import fit_bspline

    ctrl = fit_bspline(loop, 31, param="chord").control_points
    (u,), _ = ordered_closest_params(ctrl[None], [loop[::-1][::-1]])
    assert np.all(np.diff(u) >= 0) and abs(u[100] - 0.5) < 0.05  # the far end matched at the far end
