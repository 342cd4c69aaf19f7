"""training/mixes.py: the broad training mix (seeded, the same however many processes draw it, with twins) and a
user's own curves as a data set (split by curve, posed)."""

import json

import numpy as np
import pytest

from curve_vae.geometry import fit_frame, turning_angles
from curve_vae.training import mixes as M


def test_broad_mix_is_seeded_and_keeps_a_paper_share_as_the_paper_draws_it():
    a, b = M.broad_mix(400, 3), M.broad_mix(400, 3)
    np.testing.assert_array_equal(a, b)
    assert not np.array_equal(a, M.broad_mix(400, 4))
    sizes = np.ptp(a, axis=1).max(axis=1)
    posed = np.isclose(sizes, 92.6, rtol=1e-4)
    assert 0.8 < posed.mean() < 0.9  # 85%: everything but a third of the paper's 45% share is posed and framed


def test_broad_mix_is_the_same_however_many_processes_draw_it():
    n = M.CHUNK + 300  # two chunks
    one = M.broad_mix(n, 5, workers=1)
    np.testing.assert_array_equal(one, M.broad_mix(n, 5, workers=2))
    assert one.shape == (n, 161, 2) and np.isfinite(one).all()


def test_own_curves_split_by_curve_and_pose_every_training_draw(tmp_path):
    t = np.linspace(0, 1, 30)
    for i in range(10):  # ten files of one curve each, in three formats
        c = np.stack([t, np.sin(3 * t) * 0.15 * (i + 1)], 1)  # ten different shapes
        if i % 3 == 0:
            np.save(tmp_path / f"c{i}.npy", c)
        elif i % 3 == 1:
            (tmp_path / f"c{i}.csv").write_text("x,y\n" + "\n".join(f"{x},{y}" for x, y in c))
        else:
            (tmp_path / f"c{i}.json").write_text(json.dumps(c.tolist()))
    train, val, test = M.own_curves(str(tmp_path), 50, seed=0)
    assert train.shape == (50, 161, 2) and val.shape == test.shape == (1, 161, 2)
    for c in train.astype(np.float64):
        assert fit_frame(c).size == pytest.approx(92.6, rel=1e-5)
    # the held-out curves are none of the training curves, in whatever pose and spacing: the total turning does not
    # change with rotation, mirror image, scale, direction or spacing
    key = lambda c: round(float(turning_angles(c).sum()), 2)  # noqa: E731
    trained = {key(c) for c in train.astype(np.float64)}
    assert len(trained) == 8  # the 8 training curves, each drawn in many poses
    assert not {key(c) for c in np.concatenate([val, test]).astype(np.float64)} & trained


def test_own_curves_name_the_bad_file_and_line(tmp_path):
    (tmp_path / "a.csv").write_text("x,y\n0,0\n1,1\n2,oops\n3,3\n")
    with pytest.raises(ValueError, match=r"a\.csv:4: expected two numbers"):
        M.own_curves(str(tmp_path), 10, seed=0)
    with pytest.raises(ValueError, match="no such file"):
        M.own_curves(str(tmp_path / "missing"), 10, seed=0)


def test_twins_are_the_same_curves_evenly_in_their_own_parameter_in_the_same_pose():
    from curve_vae.geometry import closest_squared_distances

    drawn, even = M.broad_mix(600, 8, twins=True)
    assert drawn.shape == even.shape == (600, 161, 2)
    for c, t in zip(drawn.astype(np.float64), even.astype(np.float64)):
        diag = np.hypot(*np.ptp(c, axis=0))
        # the same curve: the points of one on the other's polyline, up to the chords of the sparser of the two
        # (a drawn spacing may leave a stretch sparse, its chords cutting a bend), in the same pose and size
        off = min(np.sqrt(closest_squared_distances(t, c)).mean(), np.sqrt(closest_squared_distances(c, t)).mean())
        assert off < 2e-4 * diag
        np.testing.assert_allclose(t[[0, -1]], c[[0, -1]], atol=1e-4)
    respaced = ~np.all(drawn == even, axis=(1, 2))
    assert 0.3 < respaced.mean() < 0.9  # the rest were drawn evenly in their parameter: their own twins
    assert np.array_equal(M.broad_mix(600, 8, twins=True), np.stack([drawn, even]))  # seeded
