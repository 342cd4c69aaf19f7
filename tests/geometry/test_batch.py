"""geometry.batch: a batch of curves of any lengths framed, posed and mapped at once, as each curve alone."""

from __future__ import annotations

import numpy as np
import pytest

from curve_vae.geometry import canonical_frame, pose_frames, random_control_points, sample_bspline
from curve_vae.geometry.batch import FrameRows, Ragged, arc_fractions_of, arc_grids, canonical_frames, pose_frames_of
from curve_vae.geometry.frame import arc_fractions, resample, turns_clockwise


def _drawn(count: int, seed: int = 0) -> list[np.ndarray]:
    """Curves as callers post them: any pose, any length, some closed, some with repeated points."""
    rng = np.random.default_rng(seed)
    out = []
    for i, c in enumerate(sample_bspline(random_control_points(rng, count), 161)):
        c = c[: rng.integers(4, 162)] @ np.linalg.qr(rng.normal(size=(2, 2)))[0] * rng.uniform(0.01, 100)
        if i % 5 == 0:
            c = np.concatenate([c, c[:1]])  # a loop
        if i % 7 == 0:
            c = np.repeat(c, 2, axis=0)  # every point twice
        out.append(c)
    return out


def test_canonical_frames_of_a_batch_are_each_curves_own():
    curves = _drawn(60)
    together = canonical_frames(curves)
    assert together == [canonical_frame(c) for c in curves]


@pytest.mark.parametrize(("chords", "flips"), [(3, True), (2, False), (1, True)])
def test_pose_frames_of_a_batch_are_each_curves_own(chords, flips):
    """Every candidate pose of every curve as frame.pose_frames gives it alone, in order (loops, repeated points,
    curves of many lengths; rotations to rounding)."""
    curves = _drawn(60, seed=3) + [np.array([[0.0, 0.0], [1.0, 0.0], [2.0, 0.0]])]  # a straight line: by its area
    for c, together in zip(curves, pose_frames_of(curves, chords=chords, flips=flips)):
        alone = pose_frames(c, chords=chords, flips=flips)
        assert [(f.mirror, f.reverse) for f in together] == [(f.mirror, f.reverse) for f in alone]
        for f, g in zip(together, alone):
            np.testing.assert_allclose([*f.center, f.size], [*g.center, g.size], rtol=1e-12, atol=1e-12 * g.size)
            assert np.isclose(np.cos(f.rotation - g.rotation), 1.0, rtol=0, atol=1e-15)
            assert np.isclose(np.sin(f.rotation - g.rotation), 0.0, rtol=0, atol=1e-12)
    with pytest.raises(ValueError, match="coincide"):
        pose_frames_of([curves[0], np.ones((5, 2))])


def test_the_canonical_frame_is_one_of_the_two_pose_candidates():
    for c in _drawn(30, seed=1):
        drawn, flipped = pose_frames(c, chords=1)
        f = canonical_frame(c)
        assert any(
            f.mirror == g.mirror and f.reverse == g.reverse and np.isclose(np.cos(f.rotation - g.rotation), 1.0)
            for g in (drawn, flipped)
        )


@pytest.mark.parametrize("model_size", [92.6, 100.0])
def test_frame_rows_map_every_curve_as_its_own_frame_does(model_size):
    curves = _drawn(40, seed=2)
    frames = canonical_frames(curves)
    batch = Ragged.of(curves)
    rows = FrameRows.of(frames)
    into = rows.to_model(batch, model_size)
    for f, c, m in zip(frames, curves, batch.split(into)):
        np.testing.assert_allclose(m, f.to_model(c, model_size), rtol=0, atol=1e-12 * model_size)
    back = rows.from_model(Ragged(into, batch.lengths), model_size)
    np.testing.assert_allclose(back, batch.points, rtol=0, atol=1e-9 * np.abs(batch.points).max())
    same = [c[: min(len(c) for c in curves)] for c in curves]  # curves of one length, as rows
    by_rows = rows.to_model_rows(np.stack(same), model_size)
    for f, c, m in zip(frames, same, by_rows):
        np.testing.assert_allclose(m, f.to_model(c, model_size), rtol=0, atol=1e-12 * model_size)


def test_points_that_all_coincide_are_refused():
    with pytest.raises(ValueError, match="coincide"):
        canonical_frames([np.ones((5, 2)), np.zeros((4, 2))])


def test_a_set_shares_its_poses_and_each_curve_keeps_its_own_box():
    from curve_vae.geometry.batch import shared_pose_frames

    curves = _drawn(4, seed=3)[1:]
    per_curve = shared_pose_frames(curves)
    assert len(per_curve) == 3 and all(len(f) == 6 for f in per_curve)
    for k in range(6):
        assert len({(round(f[k].rotation, 12), f[k].mirror) for f in per_curve}) == 1  # candidate k: one pose
    for c, frames in zip(curves, per_curve):
        posed = frames[0].to_model(c, 100.0)
        assert np.isclose(np.ptp(posed, axis=0).max(), 100.0)  # its own bounding box fills the model's


def test_a_curve_and_its_reversal_are_read_alike_in_a_set():
    from curve_vae.geometry.batch import shared_canonical_frames

    c = _drawn(1, seed=4)[0]
    fa, fb = shared_canonical_frames([c, c[::-1]])
    np.testing.assert_allclose(fa.to_model(c, 100.0), fb.to_model(c[::-1], 100.0), atol=1e-9)


def test_a_set_turns_with_its_curves():
    """Turning every curve of a set turns the set's pose with them: the posed curves stay where they were."""
    from curve_vae.geometry.batch import shared_canonical_frames

    curves = _drawn(2, seed=5)
    turn = np.array([[0.0, 1.0], [-1.0, 0.0]])
    before = shared_canonical_frames(curves)
    after = shared_canonical_frames([c @ turn for c in curves])
    for c, fa, fb in zip(curves, before, after):
        np.testing.assert_allclose(fb.to_model(c @ turn, 100.0), fa.to_model(c, 100.0), atol=1e-9)


@pytest.mark.parametrize("n_points", [4, 128, 161])
def test_arc_grids_of_a_batch_are_each_curves_own_resampling(n_points):
    """Curves of many lengths, loops and repeated points: each as frame.resample by arc length spaces it alone (to
    rounding), mirrored in x where upright and the curve turns clockwise."""
    curves = _drawn(60, seed=3)
    together = arc_grids(curves, n_points)
    upright = arc_grids(curves, n_points, upright=True)
    for c, got, up in zip(curves, together, upright):
        alone = resample(c, n_points)
        scale = np.ptp(c, axis=0).max()
        np.testing.assert_allclose(got, alone, rtol=0, atol=1e-12 * scale)
        np.testing.assert_allclose(up, alone * ([-1.0, 1.0] if turns_clockwise(c) else 1.0), rtol=0, atol=1e-12 * scale)
    assert arc_grids([], 5).shape == (0, 5, 2)


def test_arc_fractions_of_a_batch_are_each_curves_own():
    curves = _drawn(40, seed=4)
    for c, got in zip(curves, arc_fractions_of(curves)):
        np.testing.assert_allclose(got, arc_fractions(c), rtol=0, atol=1e-15)
