"""Geometry: B-spline sampling and fitting, resampling, frames, metrics."""

import numpy as np
import pytest

from curve_vae.geometry import (
    arc_length_params,
    blend_frames,
    clamped_uniform_knots,
    closest_params,
    closest_squared_distances,
    curve_length,
    evaluate_bspline,
    fit_bspline,
    fit_bspline_auto,
    fit_frame,
    mse_per_curve,
    params_at_arc_fractions,
    random_control_points,
    resample,
    sample_bspline,
    self_intersects,
    smoothness,
    spline_head,
    turning_angles,
)


def test_knots_are_clamped_and_uniform():
    k = clamped_uniform_knots(10)
    assert len(k) == 14
    np.testing.assert_array_equal(k[:4], 0)
    np.testing.assert_array_equal(k[-4:], 1)
    np.testing.assert_allclose(np.diff(k[3:11]), 1 / 7)


def test_clamped_spline_interpolates_its_end_control_points():
    ctrl = random_control_points(np.random.default_rng(1), 5)
    pts = sample_bspline(ctrl, 161)
    assert pts.shape == (5, 161, 2)
    np.testing.assert_allclose(pts[:, 0], ctrl[:, 0], atol=1e-12)
    np.testing.assert_allclose(pts[:, -1], ctrl[:, -1], atol=1e-12)


def test_control_points_lie_in_their_sectors():
    ctrl = random_control_points(np.random.default_rng(2), 1000)
    d = ctrl - 64.0
    r = np.linalg.norm(d, axis=-1)
    theta = np.mod(np.arctan2(d[..., 1], d[..., 0]), 2 * np.pi)
    assert r.max() <= 64.0
    assert np.all(np.diff(theta, axis=1) > 0), "one point per sector, in angular order"


def test_fit_recovers_control_points_of_exact_samples():
    ctrl = random_control_points(np.random.default_rng(3), 1)[0]
    fit = fit_bspline(sample_bspline(ctrl, 161), n_ctrl=10)
    np.testing.assert_allclose(fit.control_points, ctrl, atol=1e-6)
    assert fit.rms_error < 1e-9
    np.testing.assert_allclose(fit.evaluate(161), sample_bspline(ctrl, 161), atol=1e-6)


def test_fit_rejects_too_few_points():
    with pytest.raises(ValueError, match="at least n_ctrl"):
        fit_bspline(np.zeros((5, 2)), n_ctrl=10)


def test_resample_keeps_ends_and_spaces_evenly():
    ctrl = random_control_points(np.random.default_rng(4), 1)[0]
    pts = sample_bspline(ctrl, 161)
    r = resample(pts, 50)
    assert r.shape == (50, 2)
    np.testing.assert_allclose(r[[0, -1]], pts[[0, -1]])
    seg = np.linalg.norm(np.diff(r, axis=0), axis=1)
    assert seg.std() / seg.mean() < 0.02  # chords of equal arcs: nearly equal
    assert abs(curve_length(r) - curve_length(pts)) / curve_length(pts) < 0.01


def test_resample_tolerates_repeated_points():
    pts = np.array([[0, 0], [0, 0], [1, 0], [1, 0], [2, 0]], float)
    np.testing.assert_allclose(resample(pts, 5)[:, 0], [0, 0.5, 1, 1.5, 2])


def test_frame_round_trip_and_equivariance():
    rng = np.random.default_rng(5)
    pts = sample_bspline(random_control_points(rng, 1)[0])
    moved = pts * 3.5 + np.array([-1000.0, 42.0])
    f, g = fit_frame(pts), fit_frame(moved)
    np.testing.assert_allclose(f.to_model(pts, 100.0), g.to_model(moved, 100.0), atol=1e-9)
    np.testing.assert_allclose(g.from_model(g.to_model(moved, 100.0), 100.0), moved, atol=1e-9)
    with pytest.raises(ValueError, match="coincide"):
        fit_frame(np.ones((4, 2)))


def test_blend_frames_is_affine():
    a, b = fit_frame(np.array([[0, 0], [2, 1.0]])), fit_frame(np.array([[10, 10], [14, 12.0]]))
    mid = blend_frames([a, b], np.array([[0.5, 0.5]]))[0]
    assert mid.center == (6.5, 5.75) and mid.size == 3.0


def test_self_intersection():
    arc = np.stack([np.cos(np.linspace(0, 3, 50)), np.sin(np.linspace(0, 3, 50))], axis=1)
    loop = np.stack([np.cos(np.linspace(0, 7, 50)), np.sin(np.linspace(0, 7, 50)) * 0.5], axis=1)
    assert not self_intersects(arc)
    assert self_intersects(loop)
    np.testing.assert_array_equal(self_intersects(np.stack([arc, loop])), [False, True])


def test_turning_angles_of_circle_arc_are_constant():
    t = np.linspace(0, np.pi, 101)
    arc = np.stack([np.cos(t), np.sin(t)], axis=1)
    a = turning_angles(arc)
    np.testing.assert_allclose(a, np.pi / 100, rtol=1e-9)
    s = smoothness(arc[None])
    assert s["roughness"][0] < 1e-9
    noisy = arc + np.random.default_rng(0).normal(0, 1e-3, arc.shape)
    assert smoothness(noisy[None])["roughness"][0] > 0.01


def test_mse_per_curve_is_paper_eq4():
    a = np.zeros((2, 3, 2))
    b = a.copy()
    b[1, 0, 0] = 3.0  # one coordinate of six off by 3 → 9/6
    np.testing.assert_allclose(mse_per_curve(a, b), [0.0, 1.5])


def test_chord_fit_of_many_curves_and_bunched_points():
    # Chord parameters must end exactly at the last knot for every curve.
    for ctrl in random_control_points(np.random.default_rng(7), 200):
        pts = sample_bspline(ctrl, 161)
        fit = fit_bspline(pts, param="chord")
        # chord length is not the curve's own parameter, so the fit is close but not exact
        assert np.isfinite(fit.control_points).all() and fit.rms_error < 0.04 * np.ptp(pts, axis=0).max()
    bunched = np.concatenate([np.stack([np.linspace(0, 0.01, 10), np.zeros(10)], 1), [[10, 0], [20, 5]]])
    with pytest.raises(ValueError, match="cannot fit 10 control points"):
        fit_bspline(bunched, n_ctrl=10, param="chord", refine=0)


@pytest.mark.parametrize("n_ctrl", [10, 17, 24, 31])
def test_spline_head_leaves_data_set_curves_unchanged(n_ctrl):
    """The projector of the B-spline output head keeps every curve of the paper's data (knots every 1/7) exactly."""
    ctrl = random_control_points(np.random.default_rng(n_ctrl), 50)
    curves = sample_bspline(ctrl, 161)
    basis, pinv = spline_head(n_ctrl, 161)
    np.testing.assert_allclose(basis @ (pinv @ curves), curves, rtol=0, atol=1e-10)
    if n_ctrl == 10:  # the data's own basis: the control points themselves come back
        np.testing.assert_allclose(pinv @ curves, ctrl, rtol=0, atol=1e-10)


def test_spline_head_removes_a_zig_zag():
    """A period-3 zig-zag on a data curve (the stride-3 upsampling's artefact) is projected away."""
    curve = sample_bspline(random_control_points(np.random.default_rng(0), 1)[0], 161)
    zigzag = curve + 0.5 * np.array([1.0, -0.5, -0.5])[np.arange(161) % 3, None]
    basis, pinv = spline_head(31, 161)
    smooth = basis @ pinv @ zigzag
    assert smoothness(smooth)["roughness"] < 1.5 * smoothness(curve)["roughness"] < smoothness(zigzag)["roughness"]
    assert mse_per_curve(curve, smooth) < 0.02 * mse_per_curve(curve, zigzag)


def test_arc_length_params_space_points_evenly():
    ctrl = random_control_points(np.random.default_rng(2), 1)[0]
    u = arc_length_params(ctrl, 400)
    pts = evaluate_bspline(ctrl, u)
    step = np.linalg.norm(np.diff(pts, axis=0), axis=1)
    assert u[0] == 0 and u[-1] == 1 and np.all(np.diff(u) > 0)
    assert step.max() / step.min() < 1.01  # chords of a fine sampling: even up to curvature


def test_params_at_arc_fractions_reach_those_fractions_of_the_length():
    ctrl = random_control_points(np.random.default_rng(6), 1)[0]
    fractions = np.array([0.0, 0.1, 0.25, 0.5, 0.9, 1.0])
    u = params_at_arc_fractions(ctrl, fractions)
    dense = np.linspace(0, 1, 20001)
    pts = evaluate_bspline(ctrl, dense)
    s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(pts, axis=0), axis=1))])
    np.testing.assert_allclose(np.interp(u, dense, s) / s[-1], fractions, atol=1e-5)
    np.testing.assert_array_equal(arc_length_params(ctrl, 7), params_at_arc_fractions(ctrl, np.linspace(0, 1, 7)))
    # a spline collapsed to a point: the fractions themselves
    np.testing.assert_array_equal(params_at_arc_fractions(np.ones((6, 2)), fractions), fractions)


def test_closest_squared_distances_measure_to_the_polyline_with_the_ends_pinned():
    line = np.array([[0.0, 0.0], [10.0, 0.0], [10.0, 10.0]])
    points = np.array([[1.0, 1.0], [5.0, -2.0], [12.0, 5.0], [10.5, 10.0], [9.0, 9.0]])
    # inner points to their nearest segment; the first and last to the line's first and last vertex
    want = [1.0**2 + 1.0**2, 2.0**2, 2.0**2, 0.5**2, 1.0**2 + 1.0**2]
    np.testing.assert_allclose(closest_squared_distances(points, line), want)
    # the same points in any spacing along a curve are at distance 0 (up to the polyline's chords)
    ctrl = random_control_points(np.random.default_rng(7), 1)[0]
    fine = evaluate_bspline(ctrl, np.linspace(0, 1, 4001))
    anywhere = evaluate_bspline(ctrl, np.sort(np.r_[0.0, np.random.default_rng(8).uniform(0, 1, 50), 1.0]))
    assert closest_squared_distances(anywhere, fine).max() < 1e-6


def test_fit_bspline_auto_takes_the_fewest_control_points():
    ctrl = random_control_points(np.random.default_rng(4), 1)[0]
    exact = sample_bspline(ctrl, 161)
    assert len(fit_bspline_auto(exact, tolerance=1e-9, param="uniform").control_points) == 10
    seven = np.array([[0, 0], [1, 2], [2.5, 3.2], [4, 3.5], [5.5, 3], [7, 1.5], [8, 0]], float)
    fit = fit_bspline_auto(seven)
    assert 4 <= len(fit.control_points) <= 7 and fit.rms_error <= 1e-3 * np.linalg.norm(np.ptp(seven, axis=0))


def test_closest_params_find_the_parameters_of_points_on_the_spline():
    ctrl = random_control_points(np.random.default_rng(3), 1, n_ctrl=12)[0]
    u = np.sort(np.random.default_rng(4).uniform(0, 1, 40))
    pts = evaluate_bspline(ctrl, u)
    guess = np.clip(u + np.random.default_rng(5).uniform(-0.03, 0.03, len(u)), 0, 1)
    found = closest_params(ctrl, pts, guess, window=0.05)
    assert np.abs(evaluate_bspline(ctrl, found) - pts).max() < 1e-6


def test_closest_params_of_points_off_the_curve_are_their_foot_points():
    # the upper half of a near-circle, points 5 units outside it: each foot point lies on the line to the centre
    ctrl = np.array([[100.0, 0.0], [100.0, 60.0], [50.0, 100.0], [-50.0, 100.0], [-100.0, 60.0], [-100.0, 0.0]])
    u = np.linspace(0.1, 0.9, 9)
    on = evaluate_bspline(ctrl, u)
    tangent = evaluate_bspline(ctrl, u + 1e-6) - evaluate_bspline(ctrl, u - 1e-6)
    normal = np.stack([tangent[:, 1], -tangent[:, 0]], 1)
    off = on + 5.0 * normal / np.linalg.norm(normal, axis=1, keepdims=True)
    found = closest_params(ctrl, off, u, window=0.1)
    np.testing.assert_allclose(found, u, atol=1e-6)


def test_closest_params_stay_within_their_window():
    # a hairpin: the end of the curve passes close to its start; a point near the start, guessed near the start,
    # must not jump to the end's branch although that is nearer
    ctrl = np.array([[0.0, 0.0], [100.0, 0.0], [100.0, 10.0], [0.0, 10.0], [0.0, 2.0]])
    target = np.array([[1.0, 1.5]])
    near_start = closest_params(ctrl, target, np.array([0.02]), window=0.05)
    anywhere = closest_params(ctrl, target, np.array([0.5]), window=1.0)
    assert near_start[0] <= 0.07
    assert anywhere[0] > 0.9
