"""Frame and length adaptation: a caller's curve to the model's plane and point count, and a result back."""

import numpy as np
import pytest
from scipy.interpolate import BSpline

from curve_vae.geometry import (
    BeyondFloat32,
    Frame,
    clamped_uniform_knots,
    fit_frame,
    polyline_to_caller,
    pose_frames,
    random_control_points,
    spline_to_caller,
    to_model_plane,
)
from curve_vae.geometry.adapt import is_closed, joined_ends

SIZE = 92.6  # the shipped model's frame size
N = 161  # the model's point count


def _ctrl(seed: int = 1, n_ctrl: int = 10) -> np.ndarray:
    return random_control_points(np.random.default_rng(seed), 1, n_ctrl=n_ctrl)[0]


def _smooth_ctrl(n_ctrl: int = 10) -> np.ndarray:
    """Control points of a gently curved spline (a wavy 200° arc): polylines of it are close to it."""
    t = np.linspace(0.0, np.radians(200.0), n_ctrl)
    r = 40.0 + 4.0 * np.sin(3 * t)
    return np.stack([64 + r * np.cos(t), 64 + r * np.sin(t)], axis=1)


def _scipy_spline(ctrl: np.ndarray, u: np.ndarray) -> np.ndarray:
    """The clamped uniform cubic B-spline at u, evaluated by scipy's own BSpline (not the project's basis)."""
    return BSpline(clamped_uniform_knots(len(ctrl), 3), ctrl, 3)(u)


def _steps(curve: np.ndarray) -> np.ndarray:
    return np.linalg.norm(np.diff(curve, axis=0), axis=1)


# --------------------------------------------------------------------------- to the model plane


def test_a_model_length_curve_passes_untouched_in_parameter_spacing():
    pts = _scipy_spline(_ctrl(), np.linspace(0, 1, N))
    m, fractions = to_model_plane(pts, None, model_size=SIZE, n_points=N)
    np.testing.assert_array_equal(m, pts)
    assert fractions is None  # the model's points are the caller's


def test_any_length_of_the_same_curve_gives_nearly_the_same_model_input():
    ctrl = _ctrl(2) * 0.5 + 40
    model = _scipy_spline(ctrl, np.linspace(0, 1, N))
    for n in (160, 500, 1000):
        m, fractions = to_model_plane(_scipy_spline(ctrl, np.linspace(0, 1, n)), None, model_size=SIZE, n_points=N)
        assert m.shape == (N, 2)
        np.testing.assert_allclose(fractions, np.arange(n) / (n - 1))
        # on the n-point polyline's chords: off the curve by a sagitta (by arc length they would be ~16 away)
        assert np.abs(m - model).max() < 1e-3 * np.ptp(model, axis=0).max()
        np.testing.assert_array_equal(m[[0, -1]], model[[0, -1]])


def test_arc_length_spacing_spaces_a_straight_line_evenly_and_places_the_input():
    pts = np.array([[0.0, 5.0], [1.0, 5.0], [3.0, 5.0], [10.0, 5.0]])
    m, fractions = to_model_plane(pts, None, model_size=SIZE, n_points=11, spacing="arc_length")
    np.testing.assert_allclose(m, np.stack([np.arange(11.0), np.full(11, 5.0)], axis=1), atol=1e-12)
    np.testing.assert_allclose(fractions, [0.0, 0.1, 0.3, 1.0])


def test_arc_length_spacing_spaces_a_curve_evenly():
    pts = _scipy_spline(_ctrl(3), np.linspace(0, 1, 80) ** 2)  # points bunched at the start
    m, fractions = to_model_plane(pts, None, model_size=SIZE, n_points=N, spacing="arc_length")
    step = _steps(m)
    assert step.std() / step.mean() < 0.02  # chords of equal arcs of the polyline: nearly equal
    assert _steps(pts).std() / _steps(pts).mean() > 0.5  # which the input was not
    assert fractions[0] == 0 and fractions[-1] == 1 and np.all(np.diff(fractions) > 0)


def test_the_frame_fills_the_model_box_around_its_centre():
    pts = _scipy_spline(_ctrl(4), np.linspace(0, 1, 57)) * 1e-3 + [1e4, -3e4]
    m, _ = to_model_plane(pts, fit_frame(pts), model_size=SIZE, n_points=N)
    lo, hi = m.min(axis=0), m.max(axis=0)
    assert SIZE * 0.999 < (hi - lo).max() <= SIZE * (1 + 1e-12)  # resampled points stay within the input's box
    np.testing.assert_allclose((lo + hi) / 2, [64.0, 64.0], atol=0.01 * SIZE)  # the plane's centre (paper §3.1)
    chord, own = m[-1] - m[0], pts[-1] - pts[0]  # ends are kept: the chord only shifted and scaled
    np.testing.assert_allclose(chord, own * (SIZE / np.ptp(pts, axis=0).max()), rtol=1e-9)


def test_points_beyond_float32_are_refused():
    huge = np.array([[0.0, 0.0], [1e300, 0.0], [2e300, 1.0], [3.0, 3.0]])
    with pytest.raises(BeyondFloat32):
        to_model_plane(huge, None, model_size=SIZE, n_points=N)
    tiny = np.array([[0.0, 0.0], [5e-324, 0.0], [0.0, 5e-324], [5e-324, 5e-324]])  # the scale overflows
    with pytest.raises(ValueError), np.errstate(all="ignore"):  # a ValueError: geometry raises no service errors
        to_model_plane(tiny, fit_frame(tiny), model_size=SIZE, n_points=N)
    m, _ = to_model_plane(huge, fit_frame(huge), model_size=SIZE, n_points=N)  # in its own frame, it fits
    assert np.isfinite(m).all() and np.ptp(m, axis=0).max() <= SIZE


# --------------------------------------------------------------------------- back to the caller


@pytest.mark.parametrize("spacing", ["parameter", "arc_length"])
@pytest.mark.parametrize("posed", [False, True])
def test_round_trip_recovers_the_input(spacing, posed):
    pts = _scipy_spline(_smooth_ctrl(), np.linspace(0, 1, 120) ** 1.3) * 3.0 + [-500.0, 20.0]
    frame = pose_frames(pts)[1] if posed else fit_frame(pts)  # [1]: reversed and mirrored
    assert frame.reverse == posed
    m, fractions = to_model_plane(pts, frame, model_size=SIZE, n_points=N, spacing=spacing)
    back = polyline_to_caller(m, frame, model_size=SIZE, fractions=fractions)
    assert back.shape == pts.shape
    scale = np.ptp(pts, axis=0).max()
    assert np.abs(back - pts).max() < 1e-3 * scale  # polylines of a smooth curve: within a chord's sagitta
    np.testing.assert_allclose(back[[0, -1]], pts[[0, -1]], atol=1e-9 * scale)  # in the caller's order


def test_the_model_points_come_back_as_they_are_or_at_any_count():
    frame = Frame((10.0, -4.0), 2.0)
    model = _scipy_spline(_smooth_ctrl(), np.linspace(0, 1, N))
    expected = (model - 64.0) * (2.0 / SIZE) + [10.0, -4.0]
    np.testing.assert_allclose(polyline_to_caller(model, frame, model_size=SIZE), expected, atol=1e-12)
    np.testing.assert_allclose(polyline_to_caller(model, frame, model_size=SIZE, n_points=N), expected, atol=1e-12)
    np.testing.assert_array_equal(polyline_to_caller(model, None, model_size=SIZE), model)
    every_other = polyline_to_caller(model, frame, model_size=SIZE, n_points=81)
    np.testing.assert_allclose(every_other, expected[::2], atol=1e-12)  # "parameter": along the index
    even = polyline_to_caller(model, frame, model_size=SIZE, n_points=40, spacing="arc_length")
    assert _steps(even).std() / _steps(even).mean() < 1e-3


# --------------------------------------------------------------------------- splines back to the caller


@pytest.mark.parametrize("posed", [False, True])
@pytest.mark.parametrize(
    ("ask", "count"),
    [
        ({}, N),
        ({"n_points": 50}, 50),
        ({"n_points": 50, "spacing": "arc_length"}, 50),
        ({"fractions": np.linspace(0, 1, 30) ** 1.5}, 30),
    ],
    ids=["model points", "n_points", "arc_length", "fractions"],
)
def test_the_returned_spline_at_its_params_is_the_returned_points(ask, count, posed):
    ctrl = _ctrl(7, n_ctrl=31)
    frame = Frame((3.0, -2.0), 7.0, rotation=0.8, mirror=True, reverse=True) if posed else Frame((3.0, -2.0), 7.0)
    curve, c, u = spline_to_caller(ctrl, frame, model_size=SIZE, degree=3, model_points=N, **ask)
    assert len(curve) == len(u) == count
    np.testing.assert_allclose(_scipy_spline(c, u), curve, atol=1e-9)
    # and the same points are the model-plane spline's, mapped: the caller's first is the model's last if reversed
    model = _scipy_spline(ctrl, np.sort(1 - u) if posed else u)
    np.testing.assert_allclose(frame.to_model(curve, SIZE), model, atol=1e-9)
    assert u[0] == 0 and u[-1] == 1 and np.all(np.diff(u) > 0)


def test_spline_params_follow_the_spacing_asked():
    ctrl = _smooth_ctrl(31)
    _, _, u = spline_to_caller(ctrl, None, model_size=SIZE, degree=3, model_points=N)
    np.testing.assert_allclose(u, np.arange(N) / (N - 1))
    curve, _, _ = spline_to_caller(
        ctrl, None, model_size=SIZE, degree=3, model_points=N, n_points=200, spacing="arc_length"
    )
    assert _steps(curve).max() / _steps(curve).min() < 1.01
    fractions = np.array([-0.1, 0.2, 0.7, 1.3])
    _, _, u = spline_to_caller(ctrl, None, model_size=SIZE, degree=3, model_points=N, fractions=fractions)
    np.testing.assert_array_equal(u, [0.0, 0.2, 0.7, 1.0])  # clipped to the spline's range


def test_a_head_with_its_own_parameters_places_the_model_points_there_and_the_rest_between():
    ctrl = _smooth_ctrl(31)
    own = np.linspace(0, 1, N) ** 1.7  # a head that crowds its points at the start
    frame = Frame((3.0, -2.0), 7.0, rotation=0.4, reverse=True)
    curve, c, u = spline_to_caller(ctrl, frame, model_size=SIZE, degree=3, model_points=N, model_params=own)
    np.testing.assert_allclose(frame.to_model(curve, SIZE), _scipy_spline(ctrl, own), atol=1e-9)
    np.testing.assert_allclose(_scipy_spline(c, u), curve, atol=1e-9)
    _, _, u = spline_to_caller(ctrl, None, model_size=SIZE, degree=3, model_points=N, n_points=81, model_params=own)
    np.testing.assert_allclose(u, own[::2], atol=1e-15)  # "parameter": the head's spacing, at any count
    fractions = np.array([0.0, 0.25, 0.5, 1.0])
    _, _, u = spline_to_caller(
        ctrl, None, model_size=SIZE, degree=3, model_points=N, fractions=fractions, model_params=own
    )
    np.testing.assert_allclose(u, own[[0, 40, 80, 160]], atol=1e-15)  # the input's positions along the model points
    arc, _, _ = spline_to_caller(
        ctrl, None, model_size=SIZE, degree=3, model_points=N, n_points=100, spacing="arc_length", model_params=own
    )
    assert _steps(arc).max() / _steps(arc).min() < 1.01  # arc-length spacing does not depend on the head's


def test_is_closed_takes_a_repeated_first_point_at_any_scale():
    loop = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 0.0]])
    assert is_closed(loop) and is_closed(loop * 1e-12 + 5.0) and is_closed(loop * 1e12)
    assert not is_closed(loop[:-1])
    nearly = loop.copy()
    nearly[-1] = [1e-6, 0.0]
    assert not is_closed(nearly)


def test_joined_ends_meet_at_their_midpoint_and_leave_the_rest():
    pts = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.2, 0.4]])
    out = joined_ends(pts)
    np.testing.assert_array_equal(out[0], [0.1, 0.2])
    np.testing.assert_array_equal(out[-1], [0.1, 0.2])
    np.testing.assert_array_equal(out[1:-1], pts[1:-1])
    assert pts[0, 0] == 0.0  # a copy
