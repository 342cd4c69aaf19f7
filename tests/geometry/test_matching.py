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


def _reconstructed_like(count: int, seed: int) -> tuple[np.ndarray, list[np.ndarray]]:
    """Splines and curves near them as a reconstruction leaves them: open curves, loops whose ends meet (an airfoil's
    trailing edge), spirals that come back near themselves, at several lengths and noise levels."""
    rng = np.random.default_rng(seed)
    ctrl = _splines(count, seed)
    t = np.linspace(0, 1, 31)
    ctrl[::3] = np.stack([64 + 50 * np.cos(2 * np.pi * t), 64 + 20 * np.sin(2 * np.pi * t)], -1)  # loops
    ctrl[1::3] = np.stack([64 + 60 * t * np.cos(5 * np.pi * t), 64 + 60 * t * np.sin(5 * np.pi * t)], -1)  # spirals
    lengths = rng.choice([4, 7, 50, 161, 300], count)
    noise = rng.choice([0.0, 0.3, 3.0], count)
    pts = [sample_bspline(c, n) + rng.normal(0, s, (n, 2)) for c, n, s in zip(ctrl, lengths, noise)]
    return ctrl, pts


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_the_quick_match_is_the_order_keeping_programme(seed):
    """Nearest samples where they run in order, the dynamic programme elsewhere: the same placement as the programme
    run on every curve."""
    ctrl, pts = _reconstructed_like(24, seed)
    quick, d_quick = ordered_closest_params(ctrl, pts)
    every, d_every = ordered_closest_params(ctrl, pts, programme=True)
    for a, b in zip(quick, every):
        np.testing.assert_array_equal(a, b)
    np.testing.assert_array_equal(d_quick, d_every)


def test_a_curve_is_placed_alike_alone_and_in_batches_of_any_size():
    ctrl, pts = _reconstructed_like(128, seed=4)
    together, d_all = ordered_closest_params(ctrl, pts)
    for size in (1, 7):
        for start in range(0, 21, size):
            part, d = ordered_closest_params(ctrl[start : start + size], pts[start : start + size])
            for a, b in zip(part, together[start : start + size]):
                np.testing.assert_allclose(a, b, rtol=0, atol=1e-12)
            np.testing.assert_allclose(d, d_all[start : start + size], rtol=1e-12)


def test_spline_values_and_derivatives_are_scipys():
    from scipy.interpolate import BSpline

    from curve_vae.geometry import clamped_uniform_knots
    from curve_vae.geometry.bspline import spline_values

    rng = np.random.default_rng(5)
    ctrl = _splines(3)
    u = np.concatenate([[0.0, 1.0, 1 / 28, 0.5, 27 / 28], rng.uniform(0, 1, 500)])
    owner = rng.integers(0, 3, len(u))
    values = spline_values(ctrl, u, owner, order=2)
    for i, c in enumerate(ctrl):
        spline, mine = BSpline(clamped_uniform_knots(31), c, 3), owner == i
        for d, v in enumerate(values):
            ref = spline(u[mine], d)
            np.testing.assert_allclose(v[mine], ref, rtol=0, atol=1e-11 * np.abs(ref).max())
