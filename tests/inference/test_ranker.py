"""Reading pose "learned": the ranker's graph, its file, and the reading it drives (only the ranked candidates encoded;
a curve moved comes back moved)."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pytest

from curve_vae.inference import picking
from curve_vae.inference.errors import InputError
from curve_vae.inference.model.manifest import Manifest, ModelLoadError, file_entry
from curve_vae.inference.ranker import RANKED_READS, RANKER_KIND, ranker_inputs
from curve_vae.inference.reading import Reading, model_points
from curve_vae.inference.runtime import CurveRuntime
from tests.helpers import bspline_curves
from tests.parts import ranker_weights, save_npz, with_ranker


@pytest.fixture(scope="module")
def ranked_dir(closest_model_dir: Path, tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The untrained model placed closest (where the search keeps the candidate closest at the caller's points)."""
    return with_ranker(closest_model_dir, tmp_path_factory.mktemp("ranked"), ranker_weights())


@pytest.fixture(scope="module")
def ranked(ranked_dir: Path) -> CurveRuntime:
    return CurveRuntime.load(ranked_dir, providers="cpu", intra_op_threads=1, cache_bytes=0)


def test_inputs_are_the_points_about_the_centre_and_their_steps():
    pts = np.stack([np.linspace(0, 128, 161), np.full(161, 64.0)], axis=1)[None]
    x = ranker_inputs(pts)
    assert x.shape == (1, 4, 161)
    np.testing.assert_allclose(x[0, 0, [0, 80, 160]], [-1.0, 0.0, 1.0], atol=1e-6)
    np.testing.assert_allclose(x[0, 2], 0.8 / 64 * 20, rtol=1e-5)  # steps of 0.8 px, in half-sides, × 20
    assert np.all(x[0, 3] == 0)


def test_the_graph_is_a_convolution_stack(ranked: CurveRuntime):
    """Against a direct loop over the weights it was made of: conv (kernel 5, stride 2, padding 2) + ReLU three
    times, mean and max, two layers."""
    w = ranker_weights()
    pts = np.random.default_rng(1).uniform(20, 108, (3, 161, 2)).astype(np.float32)
    h = ranker_inputs(pts).astype(np.float64)
    for i in range(3):
        k, b = w[f"conv{i}_w"], w[f"conv{i}_b"]
        p = np.pad(h, ((0, 0), (0, 0), (2, 2)))
        n_out = (h.shape[2] - 1) // 2 + 1
        h = np.stack([np.einsum("bck,ock->bo", p[:, :, 2 * j : 2 * j + 5], k) for j in range(n_out)], axis=2)
        h = np.maximum(h + b[None, :, None], 0)
    z = np.concatenate([h.mean(2), h.max(2)], axis=1)
    z = np.maximum(z @ w["dense0_w"].T + w["dense0_b"], 0) @ w["dense1_w"].T + w["dense1_b"]
    assert ranked.reader.ranker is not None
    np.testing.assert_allclose(ranked.reader.ranker.scores(pts), z[:, 0], rtol=1e-4, atol=1e-5)
    assert ranked.reader.ranker.scores(np.zeros((0, 161, 2))).shape == (0,)


def test_a_graph_of_another_shape_or_numpy_weights_are_refused_with_what_to_do(ranked_dir: Path, tmp_path: Path):
    model = tmp_path / "model"
    shutil.copytree(ranked_dir, model)
    manifest = json.loads((model / "manifest.json").read_text())
    manifest["ranker"]["file"] = "encoder.onnx"  # a graph, but not of the ranker's shape
    (model / "manifest.json").write_text(json.dumps(manifest))
    with pytest.raises(
        ModelLoadError, match=r"encoder.onnx: not a usable reading ranker .*this part takes \(any, 4, 161\)"
    ):
        CurveRuntime.load(model, providers="cpu", intra_op_threads=1, cache_bytes=0)
    save_npz(model / "ranker.npz", RANKER_KIND, ranker_weights())
    manifest["ranker"]["file"] = "ranker.npz"
    manifest["files"]["ranker.npz"] = file_entry(model / "ranker.npz").model_dump()
    (model / "manifest.json").write_text(json.dumps(manifest))
    with pytest.raises(ModelLoadError, match=f"convert them to ONNX with `curve-vae ranker export {model}/ranker.npz"):
        CurveRuntime.load(model, providers="cpu", intra_op_threads=1, cache_bytes=0)


def test_the_manifest_names_the_ranker_and_checks_its_bytes(ranked_dir: Path, tmp_path: Path):
    m = Manifest.read(ranked_dir)
    assert m.ranker is not None and m.ranker.file == "ranker.onnx" and m.reading.pose == "learned"
    assert "ranker.onnx" in m.checked_files()
    broken = with_ranker(ranked_dir, tmp_path / "broken", ranker_weights())
    (broken / "ranker.onnx").write_bytes(b"not the ranker")
    with pytest.raises(ModelLoadError, match="ranker.onnx"):
        CurveRuntime.load(broken, providers="cpu", intra_op_threads=1, cache_bytes=0)


def test_learned_encodes_only_the_ranked_candidates(ranked: CurveRuntime):
    curves = list(bspline_curves(5, seed=4))
    before = ranked.graphs.rows["encoder"]
    ranked.reconstruct(curves, Reading(looks=0))  # the manifest's reading: learned
    assert ranked.graphs.rows["encoder"] - before == RANKED_READS * len(curves)
    before = ranked.graphs.rows["encoder"]
    ranked.reconstruct(curves)  # and a look again: one more encoder row a curve, at most
    assert RANKED_READS * len(curves) < ranked.graphs.rows["encoder"] - before <= (RANKED_READS + 1) * len(curves)
    before = ranked.graphs.rows["encoder"]
    ranked.reconstruct(curves, Reading(pose="search"))
    assert ranked.graphs.rows["encoder"] - before > 6 * len(curves)


def test_a_set_is_read_in_one_pose(ranked: CurveRuntime):
    curves = list(bspline_curves(3, seed=2))
    prep = ranked.prepare(curves, together=True)
    assert len({(round(f.rotation, 9), f.mirror) for f in prep.frames}) == 1


def test_a_model_without_a_ranker_names_what_is_missing(runtime: CurveRuntime):
    with pytest.raises(InputError, match="reading ranker"):
        runtime.reconstruct(list(bspline_curves(1, seed=1)), Reading(pose="learned"))


def test_the_second_read_is_never_the_first_again():
    """A symmetric curve reversed and mirrored end for end is itself: that candidate is skipped for the next one."""
    from curve_vae.inference.picking import distinct

    a = np.zeros((161, 2))
    models = np.stack([a, a + 1e-5, a + 1.0, a + 2.0])
    assert distinct(np.array([0, 1, 2, 3]), models, 2).tolist() == [0, 2]
    assert distinct(np.array([3, 0, 1]), models, 2).tolist() == [3, 0]
    assert distinct(np.array([1, 0]), models, 2).tolist() == [1]  # nothing else to read


def test_a_symmetric_curve_is_read_two_different_ways(ranked: CurveRuntime):
    t = np.linspace(0.0, np.pi, 80)
    half_circle = np.c_[np.cos(t), np.sin(t)] * 30 + 64
    reader = ranked.reader
    stage = reader._candidates([half_circle], [0], Reading(pose="learned", spacing="parameter"))
    g = ranked.graphs
    models, _ = model_points([half_circle], [0], stage, n_points=g.n_points, model_size=g.model_size)
    (keep,) = picking.ranked(reader.ranker, stage, models, shared=False, count=2)  # its two best, best first
    assert len(keep) == 2 and np.abs(models[keep[0]] - models[keep[1]]).max() > 1e-3
    assert any(np.abs(models[i] - models[j]).max() < 1e-6 for i in range(6) for j in range(i))  # twins exist
