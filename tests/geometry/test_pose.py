"""Poses: candidate frames that make direction, mirror image and rotation of a posted curve not matter."""

import numpy as np
import pytest

from curve_vae.geometry import Frame, blend_frames, pose_frames, random_control_points, sample_bspline, signed_turning
from curve_vae.geometry.frame import POSE_CHORDS, chord_heading

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
