"""geometry.frame: frames (bounding box, pose) that bring a curve to the model and back, blended frames, the pose
candidates that make direction, mirror image and rotation of a posted curve not matter, the canonical pose, and
arc-length helpers (cumulative length, fractions, resampling)."""

import numpy as np
import pytest

from curve_vae.geometry import (
    MODEL_SIZE,
    Frame,
    arc_centroid,
    arc_fractions,
    at_fractions,
    blend_frames,
    cumulative_length,
    curve_length,
    fit_frame,
    pose_frames,
    posed_frame,
    random_control_points,
    resample,
    sample_bspline,
    signed_turning,
    turns_clockwise,
)
from curve_vae.geometry.frame import MODEL_CENTER, POSE_CHORDS, chord_heading, resample_index

SIZE = 92.6


def _rot(a: float) -> np.ndarray:
    return np.array([[np.cos(a), np.sin(a)], [-np.sin(a), np.cos(a)]])


def _curve(seed: int = 1) -> np.ndarray:
    return sample_bspline(random_control_points(np.random.default_rng(seed), 1), 161)[0] * 0.3 + [40.0, -7.0]


MOVES = {
    "reversed": lambda c: c[::-1],
    "mirrored": lambda c: c * [-1.0, 1.0],
    "rotated": lambda c: c @ _rot(2.1),
    "all three, shifted": lambda c: (c[::-1] * [1.0, -1.0]) @ _rot(-0.7) + 5.0,
}


@pytest.mark.parametrize("move", MOVES)
def test_a_moved_curve_gets_the_same_candidates_in_the_model_plane(move):
    c = _curve()
    mine = [f.to_model(c, SIZE) for f in pose_frames(c)]
    moved = MOVES[move](c)
    theirs = [f.to_model(moved, SIZE) for f in pose_frames(moved)]
    assert len(mine) == len(theirs) == 2 * len(POSE_CHORDS)
    for m in theirs:  # every candidate of the moved curve is one of the curve's own, point for point
        assert min(np.abs(m - x).max() for x in mine) < 1e-9


def test_candidates_turn_counter_clockwise_with_the_chord_where_asked():
    c = _curve(3)
    for f in pose_frames(c):
        m = f.to_model(c, SIZE)
        assert signed_turning(m) > 0
        assert np.ptp(m, axis=0).max() == pytest.approx(SIZE)
        assert chord_heading(m) == pytest.approx(min(POSE_CHORDS, key=lambda t: abs(t - chord_heading(m))), abs=1e-9)


def test_posed_frame_round_trip_and_parameters():
    c = _curve(4)
    f = Frame((3.0, -2.0), 7.0, rotation=0.8, mirror=True, reverse=True)
    m = f.to_model(c, SIZE)
    np.testing.assert_allclose(f.from_model(m, SIZE), c, atol=1e-12)
    np.testing.assert_allclose(m[0], f.to_model(c[-1:], SIZE)[0])  # the order is reversed
    u = np.array([0.0, 0.25, 1.0])
    np.testing.assert_allclose(f.to_caller_params(u), [0.0, 0.75, 1.0])


def test_a_closed_loop_faces_its_opening_to_where_it_starts():
    t = np.linspace(0, 2 * np.pi, 100)
    loop = np.stack([np.cos(t), np.sin(t)], 1)  # starts on the right, counter-clockwise, closed
    assert chord_heading(loop) == pytest.approx(-np.pi / 2)
    assert pose_frames(loop)[0].rotation == pytest.approx(0.0, abs=1e-12)


def test_blending_a_curve_with_its_reversal_gives_the_curve():
    c = _curve(5)
    fa = pose_frames(c)[0]
    fb = next(f for f in pose_frames(c[::-1]) if np.allclose(f.to_model(c[::-1], SIZE), fa.to_model(c, SIZE)))
    for w in (0.2, 0.5, 0.9):
        g = blend_frames([fa, fb], np.array([[w, 1 - w]]))[0]
        placed = g.from_model(fa.to_model(c, SIZE), SIZE)
        np.testing.assert_allclose(placed if g.reverse == fa.reverse else placed[::-1], c, atol=1e-9)


def test_rotations_blend_the_short_way_round_within_a_mirror_parity():
    a = Frame((0.0, 0.0), 1.0, rotation=np.pi - 0.1)
    b = Frame((0.0, 0.0), 1.0, rotation=-np.pi + 0.1)
    assert abs(blend_frames([a, b], np.array([[0.5, 0.5]]))[0].rotation) == pytest.approx(np.pi)
    m = Frame((0.0, 0.0), 1.0, rotation=1.0, mirror=True)
    assert blend_frames([a, m], np.array([[0.6, 0.4]]))[0].rotation == pytest.approx(a.rotation)


def _moves(c: np.ndarray, rng: np.random.Generator) -> list[np.ndarray]:
    a = rng.uniform(0, 2 * np.pi)
    turn = np.array([[np.cos(a), np.sin(a)], [-np.sin(a), np.cos(a)]])
    return [c[::-1], c * [-1.0, 1.0], c @ turn * 3.7 + 100, (c * [-1.0, 1.0])[::-1] @ turn * 0.01]


def test_the_canonical_pose_is_the_same_for_a_curve_its_reversal_mirror_image_and_rotations():
    """Open curves, closed-looking loops (an airfoil's trailing edge), S-bends: every move comes to the same posed
    points, to rounding."""
    from curve_vae.geometry import canonical_frame

    rng = np.random.default_rng(5)
    t = np.linspace(0, 1, 120)
    curves = [
        *sample_bspline(random_control_points(rng, 20), 161),  # the paper's curves, many nearly closed
        np.stack([np.cos(6 * t), 0.2 * np.sin(6 * t) + t], 1),  # a loop
        np.stack([t, 0.3 * np.sin(2 * np.pi * t * 1.3)], 1),  # an S-bend
    ]
    for c in curves:
        base = canonical_frame(c).to_model(c, 92.6)
        for moved in _moves(c, rng):
            np.testing.assert_allclose(canonical_frame(moved).to_model(moved, 92.6), base, atol=1e-9)
        f = canonical_frame(c)
        posed = f.to_model(c, 92.6)
        assert signed_turning(posed) >= 0 and np.ptp(posed, axis=0).max() == pytest.approx(92.6)


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


# ------------------------------------------------------------------ arc length

#: a polyline whose lengths are known: 3, then 4 (a 3-4-5 corner), then 0 (a repeated point)
CORNER = np.array([[0.0, 0.0], [3.0, 0.0], [3.0, 4.0], [3.0, 4.0]])


def test_cumulative_length_and_arc_fractions_of_a_known_polyline():
    np.testing.assert_array_equal(cumulative_length(CORNER), [0.0, 3.0, 7.0, 7.0])
    np.testing.assert_allclose(arc_fractions(CORNER), [0.0, 3 / 7, 1.0, 1.0])
    with pytest.raises(ValueError, match="all points coincide"):
        arc_fractions(np.full((5, 2), 2.5))


def test_at_fractions_reads_a_polyline_along_its_index():
    line = np.array([[0.0, 0.0], [10.0, 0.0], [10.0, 20.0]])  # point j at fraction j/2
    got = at_fractions(line, np.array([0.0, 0.25, 0.5, 0.75, 1.0, -1.0, 2.0]))
    np.testing.assert_allclose(got, [[0, 0], [5, 0], [10, 0], [10, 10], [10, 20], [0, 0], [10, 20]])


def test_resample_index_is_at_fractions_of_each_curve_at_once():
    curves = sample_bspline(random_control_points(np.random.default_rng(3), 4), 30)
    out = resample_index(curves, 17)
    for c, o in zip(curves, out):
        np.testing.assert_allclose(o, at_fractions(c, np.linspace(0, 1, 17)), atol=1e-12)
    same = resample_index(curves, 30)
    np.testing.assert_array_equal(same, curves)
    assert not np.shares_memory(same, curves)  # a copy: the caller's array is never handed back to be changed


def test_resample_by_parameter_and_a_bad_spacing():
    pts = np.array([[0.0, 0.0], [1.0, 0.0], [5.0, 0.0]])  # uneven steps: "parameter" keeps to the index
    np.testing.assert_allclose(resample(pts, 5, spacing="parameter")[:, 0], [0.0, 0.5, 1.0, 3.0, 5.0])
    np.testing.assert_allclose(resample(pts, 5)[:, 0], [0.0, 1.25, 2.5, 3.75, 5.0])  # arc length: even
    with pytest.raises(ValueError, match="spacing must be 'arc_length' or 'parameter', got 'even'"):
        resample(pts, 5, spacing="even")
    with pytest.raises(ValueError, match="all points coincide"):
        resample(np.ones((4, 2)), 9)


def test_arc_centroid_weighs_segments_by_length_not_points_by_count():
    # an L of two sides of length 2: midpoints (1, 0) and (2, 1), equal weights, however many points the first has
    ell = np.array([[0.0, 0.0], [0.5, 0.0], [1.0, 0.0], [1.5, 0.0], [2.0, 0.0], [2.0, 2.0]])
    np.testing.assert_allclose(arc_centroid(ell), [1.5, 0.5])
    np.testing.assert_allclose(arc_centroid(np.array([[1.0, 2.0], [1.0, 2.0]])), [1.0, 2.0])  # a point: itself


# ------------------------------------------------------------------ turning and chords

SEMICIRCLE = np.stack([np.cos(np.linspace(0, np.pi, 101)), np.sin(np.linspace(0, np.pi, 101))], axis=1)


def test_signed_turning_of_a_half_circle():
    # 100 chords 1.8° apart: 99 turns of π/100 each, counter-clockwise
    assert signed_turning(SEMICIRCLE) == pytest.approx(0.99 * np.pi, rel=1e-12)
    assert signed_turning(SEMICIRCLE[::-1]) == pytest.approx(-0.99 * np.pi, rel=1e-12)
    assert signed_turning(SEMICIRCLE * [-1.0, 1.0]) == pytest.approx(-0.99 * np.pi, rel=1e-12)
    assert signed_turning(np.array([[0.0, 0.0], [1.0, 1.0]])) == 0.0  # one segment turns nowhere


TURNS = {
    "counter-clockwise arc": (SEMICIRCLE, False),
    "clockwise arc": (SEMICIRCLE[::-1], True),
    # S-bends turn by zero: the area they enclose with their chord decides, and changes sign when mirrored
    "S-bend": (np.array([[0.0, 0.0], [2.0, 0.0], [2.0, 1.0], [3.0, 1.0]]), False),  # left, then right: area +1
    "mirrored S-bend": (np.array([[0.0, 0.0], [-2.0, 0.0], [-2.0, 1.0], [-3.0, 1.0]]), True),
    "straight line": (np.array([[0.0, 0.0], [1.0, 1.0], [2.0, 2.0]]), False),
}


@pytest.mark.parametrize("points, clockwise", TURNS.values(), ids=TURNS.keys())
def test_turns_clockwise(points, clockwise):
    assert turns_clockwise(points) is clockwise


def test_chord_heading_of_an_open_curve_is_its_chords_direction():
    assert chord_heading(np.array([[1.0, 1.0], [1.5, 3.0], [1.0, 5.0]])) == pytest.approx(np.pi / 2)
    assert chord_heading(SEMICIRCLE) == pytest.approx(np.pi)


def test_pose_frames_of_coincident_points_are_refused():
    with pytest.raises(ValueError, match="all points coincide"):
        pose_frames(np.ones((10, 2)))


def test_a_posed_frame_fills_the_model_box_in_its_pose():
    # a 4 × 1 bar along x turned a quarter: its box in the posed orientation is 1 wide and 4 high
    bar = np.array([[0.0, 0.0], [4.0, 0.0], [4.0, 1.0], [0.0, 1.0]]) + [10.0, -3.0]
    f = posed_frame(bar, np.pi / 2)
    assert f.size == pytest.approx(4.0) and f.center == pytest.approx((12.0, -2.5)) and f.posed
    m = f.to_model(bar, MODEL_SIZE)
    np.testing.assert_allclose(np.ptp(m, axis=0), [MODEL_SIZE / 4, MODEL_SIZE], atol=1e-9)
    np.testing.assert_allclose((m.min(axis=0) + m.max(axis=0)) / 2, MODEL_CENTER, atol=1e-9)
    np.testing.assert_allclose(f.from_model(m, MODEL_SIZE), bar, atol=1e-12)


def test_an_unposed_frame_is_a_shift_and_a_scale():
    f = fit_frame(np.array([[2.0, 1.0], [6.0, 3.0]]))  # box 4 × 2 about (4, 2)
    assert f == Frame((4.0, 2.0), 4.0) and not f.posed
    np.testing.assert_allclose(f.to_model(np.array([[2.0, 1.0], [6.0, 3.0]]), 100.0), [[14.0, 39.0], [114.0, 89.0]])
    np.testing.assert_array_equal(f.to_caller_params(np.array([0.0, 0.3, 1.0])), [0.0, 0.3, 1.0])
