"""geometry.bspline: clamped uniform B-splines — knots, the paper's random control points, sampling and evaluation
(checked against scipy.interpolate.BSpline and the Bernstein form), least-squares fits, the fixed output head,
arc-length parameters and closest points."""

from math import comb

import numpy as np
import pytest
from scipy.interpolate import BSpline

from curve_vae.geometry import (
    arc_length_params,
    clamped_uniform_knots,
    closest_params,
    evaluate_bspline,
    fit_bspline,
    fit_bspline_auto,
    mse_per_curve,
    params_at_arc_fractions,
    random_control_points,
    sample_bspline,
    smoothness,
    spline_head,
)
from curve_vae.geometry.bspline import basis_and_slope, spline_values


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


# ------------------------------------------------------------------ evaluation against independent references

#: (n_ctrl, degree) of the splines evaluated against scipy: the paper's 10, the head's 31, and other degrees
SHAPES = {"cubic, 10": (10, 3), "cubic, 31": (31, 3), "quadratic, 7": (7, 2), "quintic, 12": (12, 5)}


def _reference(ctrl: np.ndarray, degree: int) -> BSpline:
    """scipy's spline on the clamped uniform knots, built here from their definition, not from the module."""
    n = len(ctrl)
    knots = np.r_[np.zeros(degree), np.linspace(0.0, 1.0, n - degree + 1), np.ones(degree)]
    return BSpline(knots, ctrl, degree)


@pytest.mark.parametrize("n_ctrl, degree", SHAPES.values(), ids=SHAPES.keys())
def test_sampling_and_evaluation_agree_with_scipy(n_ctrl, degree):
    ctrl = np.random.default_rng(n_ctrl + degree).normal(0, 30, (n_ctrl, 2))
    want = _reference(ctrl, degree)
    np.testing.assert_allclose(sample_bspline(ctrl, 57, degree), want(np.linspace(0, 1, 57)), atol=1e-10)
    u = np.random.default_rng(1).uniform(0, 1, 40)
    np.testing.assert_allclose(evaluate_bspline(ctrl, u, degree), want(u), atol=1e-10)
    # parameters outside [0, 1] are clipped to the ends, where a clamped spline meets its end control points
    np.testing.assert_allclose(evaluate_bspline(ctrl, [-0.5, 1.5], degree), ctrl[[0, -1]], atol=1e-12)


def test_four_control_points_make_the_cubic_bezier_curve():
    # with degree + 1 control points the knots are [0,0,0,0,1,1,1,1]: the Bernstein form, written out here
    ctrl = np.array([[0.0, 0.0], [1.0, 3.0], [4.0, 3.0], [5.0, -1.0]])
    t = np.linspace(0, 1, 11)[:, None]
    bezier = sum(comb(3, k) * t**k * (1 - t) ** (3 - k) * ctrl[k] for k in range(4))
    np.testing.assert_allclose(evaluate_bspline(ctrl, t[:, 0]), bezier, atol=1e-12)
    np.testing.assert_allclose(sample_bspline(ctrl, 11), bezier, atol=1e-12)


def test_a_batch_is_sampled_curve_by_curve():
    ctrl = random_control_points(np.random.default_rng(9), 3)
    batch = sample_bspline(ctrl, 40)
    assert batch.shape == (3, 40, 2)
    for c, b in zip(ctrl, batch):
        np.testing.assert_allclose(b, _reference(c, 3)(np.linspace(0, 1, 40)), atol=1e-10)


@pytest.mark.parametrize("n_ctrl, degree", SHAPES.values(), ids=SHAPES.keys())
def test_spline_values_give_each_points_own_spline_and_its_derivatives(n_ctrl, degree):
    rng = np.random.default_rng(n_ctrl * degree)
    ctrl = rng.normal(0, 10, (3, n_ctrl, 2))
    u = np.r_[0.0, rng.uniform(0, 1, 30), 1.0]  # the ends too: the last span holds u = 1
    owner = rng.integers(0, 3, len(u))
    values = spline_values(ctrl, u, owner, degree=degree, order=2)
    assert len(values) == 3
    for d, got in enumerate(values):
        want = np.array(
            [
                _reference(ctrl[o], degree).derivative(d)(x) if d else _reference(ctrl[o], degree)(x)
                for o, x in zip(owner, u)
            ]
        )
        np.testing.assert_allclose(got, want, rtol=1e-9, atol=1e-8 * np.abs(want).max())
    # without an owner every point is on the first spline
    np.testing.assert_allclose(spline_values(ctrl, u, degree=degree)[0], _reference(ctrl[0], degree)(u), atol=1e-9)


def test_basis_and_slope_are_scipys_basis_and_its_derivative():
    u = np.array([-0.2, 0.0, 0.13, 0.5, 0.77, 1.0, 1.4])
    basis, slope = basis_and_slope(u, 8)
    clipped = np.clip(u, 0, 1)
    eye = _reference(np.eye(8), 3)
    np.testing.assert_allclose(basis, eye(clipped), atol=1e-12)
    np.testing.assert_allclose(slope, eye.derivative()(clipped), atol=1e-9)
    np.testing.assert_allclose(basis.sum(axis=1), 1.0, atol=1e-12)  # a partition of unity
    np.testing.assert_allclose(slope.sum(axis=1), 0.0, atol=1e-9)


# ------------------------------------------------------------------ bad input


@pytest.mark.parametrize("n_ctrl", [1, 3], ids=["one", "degree"])
def test_knots_need_more_control_points_than_the_degree(n_ctrl):
    with pytest.raises(ValueError, match=f"need more than 3 control points for degree 3, got {n_ctrl}"):
        clamped_uniform_knots(n_ctrl)


BAD_FITS = {
    "three coordinates": (np.zeros((20, 3)), {}, r"points must have shape \(n, 2\), got \(20, 3\)"),
    "flat list": (np.zeros(20), {}, r"points must have shape \(n, 2\)"),
    "unknown param": (np.random.default_rng(0).normal(size=(20, 2)), {"param": "arc"}, "param must be 'uniform' or"),
    "coincident, chord": (np.ones((20, 2)), {"param": "chord"}, "all points coincide"),
}


@pytest.mark.parametrize("points, options, message", BAD_FITS.values(), ids=BAD_FITS.keys())
def test_fit_names_what_is_wrong_with_its_input(points, options, message):
    with pytest.raises(ValueError, match=message):
        fit_bspline(points, **options)


@pytest.mark.parametrize("shape", [(3, 2), (10, 3)], ids=["three points", "three coordinates"])
def test_auto_fit_needs_four_points_in_the_plane(shape):
    with pytest.raises(ValueError, match="points must have shape"):
        fit_bspline_auto(np.random.default_rng(0).normal(size=shape))


def test_auto_fit_of_a_straight_line_takes_four_control_points():
    # a line is a cubic with any number of control points: the fewest tried, exact (chord parameters are its own)
    line = np.stack([np.linspace(0, 10, 30), np.linspace(0, 5, 30)], axis=1)
    fit = fit_bspline_auto(line)
    assert len(fit.control_points) == 4 and fit.rms_error < 1e-9
