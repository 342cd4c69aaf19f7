"""`natural_params`: where a curve's points sit on the cubic B-spline that fits them closest, and the "natural"
reading of a curve at even steps of them — the spacing of the paper's curves, whatever spacing a curve came in."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.interpolate import BSpline

from curve_vae.geometry import (
    arc_fractions,
    clamped_uniform_knots,
    natural_params,
    natural_readings,
    random_control_points,
    resample,
    sample_bspline,
    to_model_plane,
)


def _spiral_spline() -> np.ndarray:
    """161 points of a 10-control-point B-spline evenly in its parameter, turning twice around."""
    a = np.linspace(0.3, 3.2 * np.pi, 10)
    return sample_bspline(np.stack([(6 + 5 * a) * np.cos(a), (6 + 5 * a) * np.sin(a)], axis=1), 161)


def _paper_curves(count: int) -> np.ndarray:
    return sample_bspline(random_control_points(np.random.default_rng(5), count), 161)


def _rel(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.sqrt(((a - b) ** 2).sum(-1).mean()) / np.hypot(*np.ptp(b, axis=0)))


def _fit_rms(points: np.ndarray, u: np.ndarray) -> float:
    """RMS distance of points to the least-squares 10-control-point spline through them at parameters u."""
    basis = BSpline.design_matrix(u, clamped_uniform_knots(10), 3).toarray()
    return float(np.sqrt(((basis @ np.linalg.lstsq(basis, points, rcond=None)[0] - points) ** 2).sum(-1).mean()))


def test_the_parameters_are_those_of_a_spline_that_passes_through_the_points():
    for drawn in [resample(_spiral_spline(), 161), *(resample(c, 120) for c in _paper_curves(5))]:
        u = natural_params(drawn)
        assert u[0] == 0.0 and u[-1] == 1.0 and np.all(np.diff(u) >= 0)
        # far closer than the spline at the points' arc-length fractions (the start), within 0.3% of the diagonal
        assert _fit_rms(drawn, u) < 0.2 * _fit_rms(drawn, arc_fractions(drawn))
        assert _fit_rms(drawn, u) < 3e-3 * np.hypot(*np.ptp(drawn, axis=0))


def test_the_natural_reading_of_the_papers_curves_drawn_by_arc_length_finds_their_own_spacing_for_most():
    even = _paper_curves(30)
    natural, drawn, from_arc = [], [], []
    for c in even:
        by_arc = resample(c, 161)
        readings = natural_readings(by_arc)
        read, _ = to_model_plane(by_arc, None, model_size=1.0, n_points=161, spacing="natural")
        natural.append(_rel(read, c))
        drawn.append(_rel(by_arc, c))
        read, _ = to_model_plane(by_arc, None, model_size=1.0, n_points=161, spacing="natural", natural=readings[-1])
        from_arc.append(_rel(read, c))
    natural, drawn, from_arc = np.array(natural), np.array(drawn), np.array(from_arc)
    # point by point against the samples evenly in the parameter: most curves are read at their own spacing (to 0.1%
    # of the diagonal), none of them as drawn, and far fewer by the fit from the arc-length fractions (the second
    # reading, or the only one where that fit came closest; scripts/natural_spacing.py measures it on the paper's
    # test curves)
    assert np.mean(natural < 1e-3) >= 0.4, np.sort(natural)
    assert np.mean(drawn < 1e-3) == 0 and np.mean(from_arc < 1e-3) <= 0.5 * np.mean(natural < 1e-3)
    assert np.mean(natural < drawn) >= 0.8


def test_the_readings_are_the_closest_fit_first_then_the_fit_from_the_arc_length_fractions():
    for c in _paper_curves(8):
        drawn = resample(c, 140)
        readings = natural_readings(drawn)
        assert 1 <= len(readings) <= 2
        np.testing.assert_array_equal(readings[0], natural_params(drawn))
        for u in readings:
            assert u[0] == 0.0 and u[-1] == 1.0 and np.all(np.diff(u) >= 0)
        assert _fit_rms(drawn, readings[0]) < _fit_rms(drawn, readings[-1]) * (1 + 1e-9)
        # the reversed curve's readings are these, reversed
        for u, back in zip(readings, natural_readings(drawn[::-1]), strict=True):
            np.testing.assert_allclose(back, 1.0 - u[::-1], atol=1e-9)


def test_the_parameters_follow_the_shape_not_its_pose_scale_or_direction():
    even = _spiral_spline()
    drawn = resample(even, 120)
    u = natural_params(drawn)
    turn = np.array([[np.cos(1.1), np.sin(1.1)], [-np.sin(1.1), np.cos(1.1)]])
    moved = (drawn * [-1.0, 1.0]) @ turn * 37.0 + [500.0, -8.0]
    np.testing.assert_allclose(natural_params(moved), u, atol=1e-6)
    np.testing.assert_allclose(natural_params(drawn[::-1]), 1.0 - u[::-1], atol=1e-9)


def test_short_curves_keep_their_arc_length_fractions_and_a_point_is_refused():
    pts = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [3.0, 1.0], [3.0, 4.0]])
    np.testing.assert_array_equal(natural_params(pts), arc_fractions(pts))
    with pytest.raises(ValueError, match="all points coincide"):
        natural_params(np.ones((30, 2)))


def test_the_natural_reading_says_where_the_callers_points_sit():
    even = _spiral_spline()
    drawn = resample(even, 90)
    m, fractions = to_model_plane(drawn, None, model_size=1.0, n_points=161, spacing="natural")
    np.testing.assert_allclose(fractions, natural_params(drawn))
    # the caller's points, read back from the model's points at their fractions, are where they were
    back = np.stack([np.interp(fractions, np.linspace(0, 1, 161), m[:, k]) for k in range(2)], axis=1)
    assert _rel(back, drawn) < 1e-3


def test_a_curve_that_turns_alike_at_both_ends_is_fitted_either_way_it_is_listed():
    a = np.linspace(0.0, 0.8 * np.pi, 161)
    arc = np.stack([np.cos(a), np.sin(a)], axis=1)  # turns evenly: the turning's centre is at the middle, to rounding
    for c in (arc, arc[::-1], arc * [-1.0, 1.0]):
        u = natural_params(c)
        assert u[0] == 0.0 and u[-1] == 1.0 and np.all(np.diff(u) >= 0)
        np.testing.assert_allclose(u, np.linspace(0, 1, 161), atol=0.02)  # an arc's even spacing fits as it is


def test_a_long_curve_is_fitted_on_some_of_its_points_and_the_rest_follow_by_arc_length():
    c = _paper_curves(1)[0]
    few, many = resample(c, 161), resample(c, 4096)  # both evenly by arc length: index fraction = arc fraction
    u_few, u_many = natural_params(few), natural_params(many)  # the second fits 321 of its points (bounded cost)
    np.testing.assert_allclose(np.interp(np.linspace(0, 1, 161), np.linspace(0, 1, 4096), u_many), u_few, atol=2e-3)
    assert u_many[0] == 0.0 and u_many[-1] == 1.0 and np.all(np.diff(u_many) >= 0)
    np.testing.assert_allclose(natural_params(many[::-1]), 1.0 - u_many[::-1], atol=1e-9)


def test_the_scout_and_total_steps_are_the_callers():
    """`scout` and `steps` set the fit's two stages: the defaults are NATURAL_SCOUT_STEPS and 40, and a shorter fit
    still gives parameters from 0 to 1 in order, near the full fit's."""
    from curve_vae.geometry.natural import NATURAL_SCOUT_STEPS, natural_readings_of

    rng = np.random.default_rng(5)
    curve = resample(sample_bspline(random_control_points(rng, 1), 641)[0], 161)
    full = natural_readings_of([curve])[0]
    assert all(
        np.array_equal(a, b) for a, b in zip(full, natural_readings_of([curve], steps=40, scout=NATURAL_SCOUT_STEPS)[0])
    )
    short = natural_readings_of([curve], steps=24, scout=8)[0]
    for u in short:
        assert u[0] == 0.0 and u[-1] == 1.0 and (np.diff(u) >= 0).all()
    assert np.abs(short[0] - full[0]).max() < 0.05


def test_a_guess_is_where_the_fit_starts_beside_the_arc_length_fractions():
    """`guess` replaces the stretched starts: given the generator's own parameters of paper curves drawn by arc length,
    the fit with no steps gives them back (clipped to rise from 0 to 1) and the arc-length fractions as the second
    reading; the guess sees each curve as the fit does (from the end it turns most towards)."""
    from curve_vae.geometry.bspline import arc_length_params, evaluate_bspline
    from curve_vae.geometry.natural import natural_readings_of

    rng = np.random.default_rng(8)
    ctrl = random_control_points(rng, 4)
    truth = [arc_length_params(c, 150) for c in ctrl]
    curves = [evaluate_bspline(c, u) for c, u in zip(ctrl, truth)]
    seen: list[int] = []

    def guess(fitted):
        seen.append(len(fitted))
        out = []
        for pts in fitted:
            k = next(i for i, c in enumerate(curves) if np.allclose(_unit(c), pts) or np.allclose(_unit(c)[::-1], pts))
            flipped = not np.allclose(_unit(curves[k]), pts)
            out.append((1.0 - truth[k])[::-1] if flipped else truth[k])
        out[0] = out[0] * 1.5 - 0.1  # beyond [0, 1] at both ends: clipped, the ends pinned
        return out

    readings = natural_readings_of(curves, steps=0, scout=0, guess=guess)
    assert seen == [4]  # one call for the curves fitted together
    for k, (c, u, rd) in enumerate(zip(curves, truth, readings)):
        assert all(r[0] == 0.0 and r[-1] == 1.0 and (np.diff(r) >= 0).all() and r.max() <= 1.0 for r in rd)
        assert any(np.allclose(r, arc_fractions(c)) for r in rd)
        if k:  # the generator's parameters: the closer start, kept first
            assert len(rd) == 2
            np.testing.assert_allclose(rd[0], u, atol=1e-12)


def _unit(c: np.ndarray) -> np.ndarray:
    """A curve as natural_readings_of scales it: from its first point, by its larger extent."""
    return (c - c[0]) / np.ptp(c, axis=0).max()


def test_with_arc_reading_loops_and_corners_a_smooth_open_curve_gets_the_closest_starts_fit_alone():
    """arc_reading "loops_and_corners": a smooth open curve gets the closest start's reading alone; a closed-looking
    one (a loop whose ends meet, as an airfoil's outline) and one with a corner keep the arc-length start's as their
    second, as "always" gives every curve.
    Both are splines drawn by arc length, guessed at their own parameters (the closer start)."""
    from curve_vae.geometry.bspline import arc_length_params, evaluate_bspline
    from curve_vae.geometry.natural import natural_readings_of

    rng = np.random.default_rng(9)
    a = np.linspace(0.0, 2 * np.pi, 10)
    loop_ctrl = np.stack([np.cos(a) + 0.4 * np.cos(2 * a), 0.5 * np.sin(a)], axis=1) * 10  # first = last
    corner_ctrl = np.array([[0, 0], [2, 1], [4, 3], [5, 6], [5, 6], [5, 6], [6, 3], [8, 1], [10, 0], [12, 0]], float)
    ctrl = [random_control_points(rng, 1)[0], loop_ctrl, corner_ctrl]  # smooth, a loop, a corner (a triple point)
    truth = [arc_length_params(c, 150) for c in ctrl]
    curves = [evaluate_bspline(c, u) for c, u in zip(ctrl, truth)]

    def guess(fitted):
        out = []
        for pts in fitted:
            k = next(i for i, c in enumerate(curves) if np.allclose(_unit(c), pts) or np.allclose(_unit(c)[::-1], pts))
            out.append(truth[k] if np.allclose(_unit(curves[k]), pts) else (1.0 - truth[k])[::-1])
        return out

    always = natural_readings_of(curves, steps=4, scout=2, guess=guess)
    loops = natural_readings_of(curves, steps=4, scout=2, guess=guess, arc_reading="loops_and_corners")
    assert [len(r) for r in always] == [2, 2, 2]
    assert [len(r) for r in loops] == [1, 2, 2]
    np.testing.assert_array_equal(loops[0][0], always[0][0])  # the closest start's, carried on alike
    for k in (1, 2):
        for r, s in zip(loops[k], always[k]):
            np.testing.assert_array_equal(r, s)
    with pytest.raises(ValueError, match="arc_reading"):
        natural_readings_of(curves, guess=guess, arc_reading="never")


def test_the_compiled_fits_basis_is_scipys_at_every_parameter_knots_and_ends_included():
    from curve_vae.geometry.bspline import basis_and_slope, clamped_uniform_knots
    from curve_vae.geometry.natural_kernel import weights_at

    for n_ctrl in (4, 7, 10, 31):
        t = clamped_uniform_knots(n_ctrl)
        u = np.concatenate([np.random.default_rng(n_ctrl).random(500), t, [0.0, 1.0, 1e-17, 1 - 1e-16]])
        spans, b, s = weights_at(t, u, n_ctrl)
        dense_b, dense_s = np.zeros((len(u), n_ctrl)), np.zeros((len(u), n_ctrl))
        for i, sp in enumerate(spans):
            dense_b[i, sp - 3 : sp + 1], dense_s[i, sp - 3 : sp + 1] = b[i], s[i]
        basis, slope = basis_and_slope(u, n_ctrl)
        np.testing.assert_allclose(dense_b, basis, atol=1e-13)
        np.testing.assert_allclose(dense_s, slope, atol=1e-10 * n_ctrl)
