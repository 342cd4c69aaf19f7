"""training/ranker.py: the reading ranker against a real (untrained, committed) model: the exported graph is the torch
net, an old model's numpy weights convert, training resumes where it stopped, the export is read back by the runtime
as the model's reading."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pytest
import torch

from curve_vae.inference.model.manifest import Manifest, ModelLoadError, file_entry
from curve_vae.inference.ranker import RANKED_READS, RANKER_KIND, ranker_inputs
from curve_vae.inference.reading import Reading
from curve_vae.inference.runtime import CurveRuntime
from curve_vae.training.ranker import RankerNet, export_ranker, pick_ratios, train_ranker
from curve_vae.training.ranker_labels import label_curves
from tests.helpers import bspline_curves
from tests.parts import ranker_weights, save_npz


@pytest.fixture(scope="module")
def labels(closest_model_dir: Path, tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("labels")
    label_curves(closest_model_dir, out, curves=24, seed=5, chunk=8, say=lambda _: None)
    return out


def test_the_exported_graph_is_the_torch_net(tmp_path: Path, closest_model_dir: Path):
    torch.manual_seed(1)
    net = RankerNet().eval()
    torch.save({"model": net.state_dict()}, tmp_path / "ranker.pt")  # a checkpoint as training writes it
    model = tmp_path / "model"
    shutil.copytree(closest_model_dir, model)
    pts = np.asarray(bspline_curves(5, seed=2), np.float32)
    with torch.no_grad():
        expected = net(torch.from_numpy(ranker_inputs(pts))).numpy()
    export_ranker(tmp_path / "ranker.pt", model)
    runtime = CurveRuntime.load(model, providers="cpu", intra_op_threads=1, cache_bytes=0)
    assert runtime.reader.ranker is not None
    np.testing.assert_allclose(runtime.reader.ranker.scores(pts), expected, rtol=1e-4, atol=1e-5)


def test_an_old_models_numpy_ranker_converts_keeping_what_its_manifest_said(tmp_path: Path, closest_model_dir: Path):
    model = tmp_path / "model"
    shutil.copytree(closest_model_dir, model)
    npz = save_npz(model / "ranker.npz", RANKER_KIND, ranker_weights())
    manifest = json.loads((model / "manifest.json").read_text())
    manifest["files"]["ranker.npz"] = file_entry(npz).model_dump()
    manifest["ranker"] = {"file": "ranker.npz", "kind": RANKER_KIND, "note": "trained so", "held_out": {"first": 1.1}}
    (model / "manifest.json").write_text(json.dumps(manifest))
    with pytest.raises(ModelLoadError, match="numpy weights"):
        CurveRuntime.load(model, providers="cpu", intra_op_threads=1, cache_bytes=0)
    path = export_ranker(npz, model)
    after = json.loads((model / "manifest.json").read_text())
    assert path == model / "ranker.onnx" and "ranker.npz" not in after["files"] and "ranker.onnx" in after["files"]
    assert after["ranker"] == {**manifest["ranker"], "file": "ranker.onnx"}
    assert after["reading"] == manifest["reading"]  # a conversion leaves the model's reading as it was
    assert CurveRuntime.load(model, providers="cpu", intra_op_threads=1, cache_bytes=0).reader.ranker is not None


def test_pick_ratios_measure_against_the_best():
    y = np.log(np.array([[1.0, 2.0, 4.0], [3.0, 1.0, 9.0]]))
    mask = np.ones_like(y, bool)
    perfect = pick_ratios(-np.exp(-y), y, mask)
    assert perfect == {"first": 1.0, "best_of_2": 1.0}
    worst = pick_ratios(np.exp(-y), y, mask)  # ranked backwards: first picks 4 and 9, the best of two 2 and 3
    assert worst["first"] == pytest.approx(13 / 2) and worst["best_of_2"] == pytest.approx(5 / 2)


def test_training_resumes_where_it_stopped_and_exports_the_models_reading(
    labels: Path, tmp_path: Path, closest_model_dir: Path
):
    said: list[str] = []
    train_ranker(labels, tmp_path / "run", time_budget=2.0, say=said.append)
    epochs = len(said)
    assert epochs >= 1 and (tmp_path / "run" / "ranker-last.pt").is_file()
    resumed: list[str] = []
    best = train_ranker(labels, tmp_path / "run", time_budget=4.0, resume=True, say=resumed.append)
    assert resumed[0].startswith(f"resumed at epoch {epochs}")
    assert resumed[1].startswith(f"epoch {epochs + 1}:")

    model = tmp_path / "model"
    shutil.copytree(closest_model_dir, model)
    export_ranker(best, model, version="9.9.9")
    manifest = Manifest.read(model)
    assert manifest.reading.pose == "learned" and manifest.ranker is not None and manifest.version == "9.9.9"
    named = json.loads((model / "manifest.json").read_text())["ranker"]
    assert named["held_out"]["best_of_2"] >= 1.0
    trained = named["trained"]
    assert trained["label_files"] == [f.name for f in sorted(labels.glob("labels-*.npz"))]
    assert 0 < trained["seconds"] <= 4.0 + 60 and trained["curves"] > trained["held_out_curves"] > 0
    runtime = CurveRuntime.load(model, providers="cpu", intra_op_threads=1, cache_bytes=0)
    assert runtime.reading().pose == "learned"
    curves = list(bspline_curves(3, seed=6))
    before = runtime.graphs.rows["encoder"]
    runtime.reconstruct(curves, Reading(looks=0))
    assert runtime.graphs.rows["encoder"] - before == RANKED_READS * len(curves)


def test_export_can_leave_the_models_reading_and_version_as_they_were(
    labels: Path, tmp_path: Path, closest_model_dir: Path
):
    best = train_ranker(labels, tmp_path / "run", time_budget=1.0, say=lambda _: None)
    model = tmp_path / "model"
    shutil.copytree(closest_model_dir, model)
    before = Manifest.read(model)
    export_ranker(best, model, default=False)
    after = Manifest.read(model)
    assert after.ranker is not None and after.reading == before.reading and after.version == before.version
    runtime = CurveRuntime.load(model, providers="cpu", intra_op_threads=1, cache_bytes=0)
    curves = list(bspline_curves(2, seed=7))
    before_rows = runtime.graphs.rows["encoder"]
    runtime.reconstruct(curves, Reading(pose="learned", spacing="search", looks=0))  # there when asked for
    assert runtime.graphs.rows["encoder"] - before_rows == RANKED_READS * len(curves)
