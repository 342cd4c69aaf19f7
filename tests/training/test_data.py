"""The curve data set: shape, range, validity, determinism, caching."""

import numpy as np
import pytest

from curve_vae.geometry import self_intersects
from curve_vae.training.data import CurveDataset, DataConfig, default_cache, generate_curves, load_or_generate

SMALL = DataConfig(n_train=300, n_val=50, n_test=40, seed=11)


@pytest.fixture(scope="module")
def small() -> CurveDataset:
    return CurveDataset.generate(SMALL)


def test_shapes_and_dtype(small):
    assert small.train.shape == (300, 161, 2)
    assert small.val.shape == (50, 161, 2)
    assert small.test.shape == (40, 161, 2)
    assert small.test_ctrl.shape == (40, 10, 2)
    assert small.train.dtype == np.float32


def test_curves_stay_in_the_circle(small):
    # A B-spline lies in the convex hull of its control points, all inside the radius-64 disc.
    r = np.linalg.norm(np.concatenate([small.train, small.val, small.test]) - 64.0, axis=-1)
    assert r.max() <= 64.0 + 1e-3
    assert small.train.min() >= 0 and small.train.max() <= 128


def test_no_self_intersections(small):
    assert not self_intersects(small.train.astype(np.float64)).any()


def test_rejection_actually_happens():
    # Without the filter some curves do intersect; the generator must have dropped them.
    from curve_vae.geometry import random_control_points, sample_bspline

    raw = sample_bspline(random_control_points(np.random.default_rng(0), 20_000))
    assert self_intersects(raw).any()


def test_deterministic_and_prefix_stable():
    a, _ = generate_curves(100, seed=5)
    b, _ = generate_curves(100, seed=5)
    c, _ = generate_curves(30, seed=5)
    d, _ = generate_curves(100, seed=6)
    np.testing.assert_array_equal(a, b)
    np.testing.assert_array_equal(a[:30], c)
    assert not np.allclose(a, d)


@pytest.mark.parametrize("skip", [0, 37, 300, 419])
def test_skipped_curves_are_drawn_but_not_kept(skip):
    # in chunks of 64 (about 45 curves kept a chunk), the kept range starts and ends inside chunks and across them
    every, every_ctrl = generate_curves(500, seed=4, chunk=64)
    tail, tail_ctrl = generate_curves(81, seed=4, chunk=64, skip=skip)
    np.testing.assert_array_equal(tail, every[skip : skip + 81])
    np.testing.assert_array_equal(tail_ctrl, every_ctrl[skip : skip + 81])


def test_splits_are_disjoint(small):
    flat = {c.tobytes() for c in np.concatenate([small.train, small.val, small.test])}
    assert len(flat) == 390


def test_cache_round_trip_and_mismatch(tmp_path, small):
    path = tmp_path / "d.npz"
    small.save(path)
    back = load_or_generate(SMALL, path)
    np.testing.assert_array_equal(back.train, small.train)
    assert back.config == SMALL
    other = DataConfig(n_train=100, n_val=10, n_test=10, seed=11)
    before = path.read_bytes()
    with pytest.raises(ValueError, match=r"another configuration: n_train .* \(file\) vs 100 \(asked\)"):
        load_or_generate(other, path)  # a file of another configuration is neither served nor overwritten
    assert path.read_bytes() == before
    (tmp_path / "mine.npz").write_bytes(b"not a data set")
    with pytest.raises(ValueError, match="not a curve-vae data set"):
        load_or_generate(SMALL, tmp_path / "mine.npz")
    assert (tmp_path / "mine.npz").read_bytes() == b"not a data set"
    fresh = load_or_generate(other, tmp_path / "new.npz")  # a path that does not exist yet is written
    assert CurveDataset.load(tmp_path / "new.npz").config == other and fresh.train.shape == (100, 161, 2)
    assert default_cache(other) != default_cache(SMALL) and default_cache(SMALL) == default_cache(SMALL)
    assert not list(tmp_path.glob("*.tmp")), "no temporary files left behind"


def test_broad_mix_is_versioned_and_its_test_split_is_the_papers(tmp_path):
    from curve_vae.training.mixes import MIX_VERSION

    cfg = DataConfig(n_train=300, n_val=20, n_test=10, mix="broad")
    assert cfg.mix_version == MIX_VERSION and DataConfig().mix_version == 0
    ds = load_or_generate(cfg, tmp_path / "b.npz", say=False, workers=2)
    paper = generate_curves(DataConfig().n_train + 20 + 10, 0)[0][-10:]
    np.testing.assert_array_equal(ds.test, paper)  # the paper data set's test curves, whatever the mix's size
    assert ds.train.shape == (300, 161, 2) and ds.val.shape == (20, 161, 2)
    # a cache written before the mix had versions holds version 1: read as such, refused for the present one
    import json

    with np.load(tmp_path / "b.npz") as z:
        arrays = {k: z[k] for k in z.files}
    meta = json.loads(str(arrays["meta"]))
    del meta["config"]["mix_version"]
    arrays["meta"] = np.array(json.dumps(meta))
    np.savez(tmp_path / "old.npz", **arrays)
    assert CurveDataset.load(tmp_path / "old.npz").config.mix_version == 1
    with pytest.raises(ValueError, match=f"mix_version 1 .file. vs {MIX_VERSION} .asked."):
        load_or_generate(cfg, tmp_path / "old.npz")
    with pytest.raises(ValueError, match="mix_version"):
        DataConfig(mix_version=2)
    # a version no longer made is refused by name, not drawn as the present one
    with pytest.raises(ValueError, match="version 1 is no longer made"):
        load_or_generate(DataConfig(n_train=30, n_val=2, n_test=10, mix="broad", mix_version=1), tmp_path / "v1.npz")
    assert not (tmp_path / "v1.npz").exists()


def test_each_mix_version_draws_its_own_shares():
    """Version 2 (model 0.9.0's) is still drawn as it was; the present version differs from it."""
    from curve_vae.training.mixes import MIX_VERSION, MIXES, broad_mix

    assert MIX_VERSION in MIXES and 2 in MIXES
    for spec in MIXES.values():
        assert abs(sum(spec.shares.values()) - 1.0) < 1e-9 and 0 <= spec.paper_raw <= 1
        with pytest.raises(TypeError):  # a made version's shares cannot be changed by accident
            spec.shares["paper"] = 1.0  # type: ignore[index]
    old = broad_mix(400, 5, version=2)
    np.testing.assert_array_equal(old, broad_mix(400, 5, version=2))
    assert not np.array_equal(old, broad_mix(400, 5, version=MIX_VERSION))


def test_the_test_split_of_a_broad_mix_is_read_without_drawing_its_training_curves(tmp_path):
    from curve_vae.training.data import load_test_split

    cfg = DataConfig(n_train=10_000_000, n_val=20, n_test=10, mix="broad")  # far too many to draw in this test
    np.testing.assert_array_equal(load_test_split(cfg, tmp_path / "never.npz"), generate_curves(70_030, 0)[0][-10:])
    assert not (tmp_path / "never.npz").exists()


def test_a_broad_data_set_with_twins_keeps_them_through_its_cache(tmp_path):
    cfg = DataConfig(n_train=300, n_val=40, n_test=10, mix="broad", twins=True)
    ds = load_or_generate(cfg, tmp_path / "t.npz", say=False)
    assert ds.train_twins.shape == ds.train.shape and ds.val_twins.shape == ds.val.shape
    back = CurveDataset.load(tmp_path / "t.npz")
    np.testing.assert_array_equal(back.train_twins, ds.train_twins)
    np.testing.assert_array_equal(back.val_twins, ds.val_twins)
    assert back.config == cfg
    # caches without twins keep the names they had before twins existed
    assert default_cache(DataConfig(mix="broad", mix_version=3)).name == "curves-797c386517.npz"
    assert default_cache(cfg) != default_cache(DataConfig(n_train=300, n_val=40, n_test=10, mix="broad"))
    with pytest.raises(ValueError, match="twins belong to mix"):
        DataConfig(twins=True)
