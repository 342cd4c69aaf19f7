"""curve_vae/commands/model.py: `curve-vae export` and `evaluate` on a tiny seeded checkpoint. Export keeps a model
directory unless forced, checking before it reads the checkpoint, and writes what its flags ask into the manifest;
evaluate measures a checkpoint on the test split of its own data configuration."""

from __future__ import annotations

import json
from dataclasses import asdict
from pathlib import Path

import pytest
import torch

from curve_vae.cli import main
from curve_vae.training.checkpoint import CHECKPOINT_VERSION
from curve_vae.training.config import ModelConfig, TrainConfig
from curve_vae.training.data import DataConfig
from curve_vae.training.model import VAE

DATA = DataConfig(n_train=64, n_val=16, n_test=24)


@pytest.fixture(scope="module")
def checkpoint(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A training checkpoint of an untrained cnn1 (seeded), as `curve-vae train` writes one after 2 epochs."""
    torch.manual_seed(0)
    cfg = ModelConfig(variant="cnn1", latent_dim=8)
    path = tmp_path_factory.mktemp("run") / "best.pt"
    torch.save(
        {
            "version": CHECKPOINT_VERSION,
            "model_config": asdict(cfg),
            "data_config": asdict(DATA),
            "train_config": asdict(TrainConfig(epochs=2)),
            "model": VAE(cfg).eval().state_dict(),
            "state": {"epoch": 2, "best_val": 1.5, "best_epoch": 1, "trained_seconds": 3.0, "history": []},
        },
        path,
    )
    return path


def test_export_writes_what_its_flags_ask_into_the_manifest(checkpoint, tmp_path, capsys):
    out, info = tmp_path / "model", tmp_path / "info.json"
    info.write_text(json.dumps({"hardware": "a test machine"}))
    argv = ["export", "--checkpoint", str(checkpoint), "--out", str(out), "--data", str(tmp_path / "d.npz")]
    flags = ["--no-evaluate", "--no-prior", "--spline-ctrl", "10", "--placement", "index", "--version", "1.2.3"]
    assert main([*argv, *flags, "--name", "tiny", "--training-info", str(info)]) == 0
    manifest = json.loads((out / "manifest.json").read_text())
    assert manifest["name"] == "tiny" and manifest["version"] == "1.2.3" and manifest["latent_dim"] == 8
    assert manifest["spline"]["n_ctrl"] == 10 and manifest["spline"]["placement"] == "index"
    assert "prior" not in manifest and "metrics" not in manifest
    assert sorted(manifest["files"]) == ["decoder.onnx", "encoder.onnx", "vae.pt"]
    training = manifest["training"]
    assert training["epochs_run"] == 2 and training["best_epoch"] == 1 and training["hardware"] == "a test machine"
    assert training["data"]["n_train"] == 64
    said = capsys.readouterr().out.splitlines()
    assert f"exported {checkpoint} → {out}/: encoder.onnx, decoder.onnx, vae.pt, manifest.json" in said


@pytest.mark.parametrize("held", ["manifest.json", "vae.pt", "prior.npz"])
def test_export_keeps_a_model_directory_before_reading_the_checkpoint(held, tmp_path, capsys):
    out = tmp_path / "model"
    out.mkdir()
    (out / held).write_text("the user's own")
    argv = ["export", "--checkpoint", str(tmp_path / "no-such.pt"), "--out", str(out), "--no-evaluate"]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert f"already holds a model ({held}) and is left as it is: pass --force" in err
    assert [p.name for p in out.iterdir()] == [held] and (out / held).read_text() == "the user's own"


def test_export_refuses_a_placement_it_does_not_know(checkpoint, tmp_path, capsys):
    with pytest.raises(SystemExit) as e:
        main(["export", "--checkpoint", str(checkpoint), "--out", str(tmp_path / "m"), "--placement", "nearest"])
    assert e.value.code == 2 and "invalid choice: 'nearest'" in capsys.readouterr().err
    assert not (tmp_path / "m").exists()


def test_evaluate_a_checkpoint_on_its_own_test_split(checkpoint, tmp_path, capsys):
    out = tmp_path / "eval"
    argv = ["evaluate", "--checkpoint", str(checkpoint), "--data", str(tmp_path / "d.npz"), "--out", str(out)]
    assert main([*argv, "--no-figures", "--fresh-seed", "-1", "--suite-count", "0", "--morph-count", "0"]) == 0
    report = json.loads((out / "report.json").read_text())
    assert list(report["test_sets"]) == ["test"] and report["test_sets"]["test"]["n_curves"] == 24
    assert "families" not in report and "morphs" not in report
    assert not list(out.glob("*.png"))
    printed = capsys.readouterr().out
    assert "test: MSE " in printed and "24 curves" in printed and f"report: {out / 'report.json'}" in printed
