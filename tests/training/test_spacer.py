"""training/spacer.py: the spacing guesser — an old model's numpy guesser converts to a graph of the same guesses, its
examples are the generator's own parameters, training resumes where it stopped, and the export is read back by the
runtime."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pytest
import torch

from curve_vae.errors import InvalidInput
from curve_vae.inference.model.manifest import Manifest, ModelLoadError, file_entry
from curve_vae.inference.runtime import CurveRuntime
from curve_vae.inference.spacer import GRID, SPACER_KIND
from curve_vae.training.spacer import SpacerNet, export_spacer, paper_examples, train_spacer
from tests.parts import save_npz, spacer_weights


def test_an_old_models_numpy_guesser_converts_to_a_graph_of_the_same_guesses(tmp_path: Path, closest_model_dir: Path):
    model = tmp_path / "model"
    shutil.copytree(closest_model_dir, model)
    weights = spacer_weights(2)
    npz = save_npz(model / "spacer.npz", SPACER_KIND, weights)
    manifest = json.loads((model / "manifest.json").read_text())
    manifest["files"]["spacer.npz"] = file_entry(npz).model_dump()
    manifest["spacer"] = {"file": "spacer.npz", "kind": SPACER_KIND, "note": "trained so"}
    (model / "manifest.json").write_text(json.dumps(manifest))
    assert export_spacer(npz, model) == model / "spacer.onnx"
    after = json.loads((model / "manifest.json").read_text())
    assert after["spacer"] == {**manifest["spacer"], "file": "spacer.onnx"} and "spacer.npz" not in after["files"]
    x, _ = paper_examples(np.random.default_rng(2), 6)
    with torch.no_grad():
        expected = SpacerNet.from_weights(weights).eval()(torch.from_numpy(x)).numpy()
    spacer = CurveRuntime.load(model, providers="cpu", intra_op_threads=1, cache_bytes=0).reader.spacer
    assert spacer is not None
    np.testing.assert_allclose(spacer.grid_params(x), expected, atol=2e-6)
    narrower = {**weights, "dilations": np.array([1, 2])}
    with pytest.raises(InvalidInput, match="dilations"):
        SpacerNet.from_weights(narrower)


def test_the_examples_are_the_papers_curves_at_their_own_parameters_reversed_and_mirrored_alike():
    x, u = paper_examples(np.random.default_rng(3), 200)
    assert x.shape == (200, 3, GRID) and u.shape == (200, GRID)
    assert (u[:, 0] == 0).all() and np.allclose(u[:, -1], 1.0) and (np.diff(u, axis=1) >= 0).all()
    # the parameters are not the arc-length fractions (what the guess improves on), and about half the curves turn
    # each way at their start
    assert np.abs(u - np.linspace(0, 1, GRID)).max(axis=1).mean() > 0.02
    first_turn = np.sign(x[:, 0, 1:8].sum(axis=1))
    assert 0.35 < np.mean(first_turn > 0) < 0.65
    again, _ = paper_examples(np.random.default_rng(3), 200)
    np.testing.assert_array_equal(again, x)  # drawn from the seed alone: a resumed run sees the same curves


def test_training_resumes_where_it_stopped_and_the_export_is_the_models_guesser(tmp_path: Path, closest_model_dir):
    said: list[str] = []
    train_spacer(tmp_path / "run", time_budget=4.0, batch=16, say=said.append)
    assert said and said[-1].startswith("step ") and (tmp_path / "run" / "spacer-last.pt").is_file()
    steps = torch.load(tmp_path / "run" / "spacer-last.pt", weights_only=False)["state"]["step"]
    resumed: list[str] = []
    best = train_spacer(tmp_path / "run", time_budget=7.0, resume=True, say=resumed.append)
    assert resumed[0].startswith(f"resumed at step {steps}, ")
    assert torch.load(tmp_path / "run" / "spacer-last.pt", weights_only=False)["state"]["step"] > steps

    model = tmp_path / "model"
    shutil.copytree(closest_model_dir, model)
    export_spacer(best, model, version="9.9.9", meta={"note": "a test"})
    manifest = Manifest.read(model)
    assert manifest.spacer is not None and manifest.version == "9.9.9"
    named = json.loads((model / "manifest.json").read_text())["spacer"]
    assert named["note"] == "a test" and set(named["held_out"]) == {"mae", "rms"}
    assert named["trained"]["steps"] > 0 and named["trained"]["batch"] == 16
    runtime = CurveRuntime.load(model, providers="cpu", intra_op_threads=1, cache_bytes=0)
    assert runtime.reader.spacer is not None

    (model / "spacer.onnx").write_bytes((model / "spacer.onnx").read_bytes()[:-10])  # damaged after export
    with pytest.raises(ModelLoadError, match="spacer.onnx"):
        CurveRuntime.load(model, providers="cpu", intra_op_threads=1, cache_bytes=0)
