"""geometry.metrics: the reconstruction error of paper eq. 4, distances to a polyline, turning angles and smoothness
(paper §3.4), length and self-intersection — on curves whose answers are known by hand."""

import numpy as np
import pytest

from curve_vae.geometry import (
    closeness,
    closest_squared_distances,
    curve_length,
    diagonal,
    evaluate_bspline,
    mse_per_curve,
    random_control_points,
    self_intersects,
    smoothness,
    turning_angles,
)


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


def test_curve_length_of_known_polylines_and_a_batch():
    corner = np.array([[0.0, 0.0], [3.0, 0.0], [3.0, 4.0], [0.0, 0.0]])  # the 3-4-5 triangle, closed
    assert curve_length(corner) == pytest.approx(12.0)
    batch = np.stack([corner, corner * 2.0, np.zeros((4, 2))])
    np.testing.assert_allclose(curve_length(batch), [12.0, 24.0, 0.0])


def test_turning_angles_of_a_square_corner_and_a_repeated_point():
    # left 90°, then straight on, then a repeated point (a zero-length segment: no turn either side of it)
    pts = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [1.0, 2.0], [1.0, 2.0]])
    np.testing.assert_allclose(turning_angles(pts), [np.pi / 2, 0.0, 0.0], atol=1e-15)
    # a right turn counts as much as a left one: the angles are unsigned
    np.testing.assert_allclose(turning_angles(pts * [1.0, -1.0]), turning_angles(pts), atol=1e-15)


def test_smoothness_in_degrees_of_a_known_polyline():
    # turns of 0°, 90°, 45°: mean 45, sharpest 90, mean change of turning (90 + 45) / 2
    pts = np.array([[0.0, 0.0], [1.0, 0.0], [2.0, 0.0], [2.0, 1.0], [1.0, 2.0]])
    s = smoothness(pts)
    assert s["mean_turn"] == pytest.approx(45.0)
    assert s["max_turn"] == pytest.approx(90.0)
    assert s["roughness"] == pytest.approx(67.5)
    batch = smoothness(np.stack([pts, pts * 3.0]))  # a scaled copy bends alike
    np.testing.assert_allclose(batch["max_turn"], [90.0, 90.0])


SIMPLE = {
    "open arc": (np.array([[0.0, 0.0], [1.0, 1.0], [2.0, 0.0]]), False),
    "crossing": (np.array([[0.0, 0.0], [2.0, 2.0], [2.0, 0.0], [0.0, 2.0]]), True),
    # touching counts: a polyline that comes back to rest a vertex on its own first segment
    "touching": (np.array([[0.0, 0.0], [2.0, 0.0], [2.0, 1.0], [1.0, 0.0]]), True),
    "retracing": (np.array([[0.0, 0.0], [2.0, 0.0], [1.0, 0.0]]), True),
}


@pytest.mark.parametrize("curve, crosses", SIMPLE.values(), ids=SIMPLE.keys())
def test_self_intersects_crossings_and_touches(curve, crosses):
    assert self_intersects(curve) is crosses


def test_mse_per_curve_broadcasts_over_batches_and_one_curve():
    a = np.array([[0.0, 0.0], [1.0, 1.0]])
    assert float(mse_per_curve(a, a + [2.0, 0.0])) == pytest.approx(2.0)  # (4 + 0 + 4 + 0) / 4


def test_diagonal_of_one_curve_and_a_stack():
    rect = np.array([[0.0, 0.0], [3.0, 0.0], [3.0, 4.0], [1.0, 2.0]])
    assert float(diagonal(rect)) == pytest.approx(5.0)
    stack = np.stack([rect, 2 * rect, rect + 100])
    np.testing.assert_allclose(diagonal(stack), [5.0, 10.0, 5.0])
    assert float(diagonal(np.ones((3, 2)))) == 0.0  # coinciding points have no size


def test_closeness_divides_by_the_diagonal_of_each_input():
    a = np.array([[0.0, 0.0], [3.0, 0.0], [3.0, 4.0]])
    b = np.array([[0.0, 0.0], [0.0, 0.0], [0.0, 0.0], [10.0, 0.0]])
    moved = [a + [0.5, 0.0], b + [0.0, 1.0]]
    rms, worst, where = closeness([a, b], moved)
    np.testing.assert_allclose(rms, [0.5 / 5.0, 1.0 / 10.0])
    np.testing.assert_allclose(worst, [0.5 / 5.0, 1.0 / 10.0])
    assert where.shape == (2,)
    bent = a.copy()
    bent[1] += [0.0, 2.0]  # one point 2 away: RMS sqrt(4/3), the farthest 2, at index 1
    rms, worst, where = closeness([a], [bent])
    assert rms[0] == pytest.approx(np.sqrt(4 / 3) / 5.0) and worst[0] == pytest.approx(2 / 5.0) and where[0] == 1
