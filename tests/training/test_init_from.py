"""A run continued from weights with a B-spline head keeps the head unless told otherwise."""

import json
from pathlib import Path

import pytest
import torch

from curve_vae.cli import main
from curve_vae.training.config import ModelConfig
from curve_vae.training.model import VAE

TINY = ["--n-train", "128", "--n-val", "32", "--n-test", "32", "--epochs", "1", "--no-progress"]


def _start_weights(tmp_path: Path) -> Path:
    """Seeded weights of a model with the 31-control-point head (even parameters), saved as a checkpoint."""
    torch.manual_seed(0)
    start = tmp_path / "start.pt"
    torch.save(
        {"model_config": ModelConfig(spline_ctrl=31).__dict__, "model": VAE(ModelConfig(spline_ctrl=31)).state_dict()},
        start,
    )
    return start


@pytest.mark.slow
def test_init_from_keeps_the_checkpoints_spline_head(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    start = _start_weights(tmp_path)
    tiny = [*TINY, "--batch-size", "64"]
    assert main(["train", "--run-dir", "kept", "--init-from", str(start), *tiny]) == 0
    assert json.loads((tmp_path / "kept" / "config.json").read_text())["model"]["spline_ctrl"] == 31
    assert main(["train", "--run-dir", "dropped", "--init-from", str(start), "--spline-ctrl", "0", *tiny]) == 0
    assert json.loads((tmp_path / "dropped" / "config.json").read_text())["model"]["spline_ctrl"] == 0


@pytest.mark.slow
def test_init_from_weights_without_learned_parameters_widens_them_and_keeps_them(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    start = _start_weights(tmp_path)
    tiny = TINY
    assert main(["train", "--run-dir", "params", "--init-from", str(start), "--spline-params", *tiny]) == 0
    assert json.loads((tmp_path / "params" / "config.json").read_text())["model"]["spline_params"] is True
    again = tmp_path / "params" / "last.pt"
    assert main(["train", "--run-dir", "kept", "--init-from", str(again), *tiny]) == 0
    assert json.loads((tmp_path / "kept" / "config.json").read_text())["model"]["spline_params"] is True
    # the parameter channel is not dropped silently
    assert main(["train", "--run-dir", "dropped", "--init-from", str(again), "--no-spline-params", *tiny]) != 0
    assert "'spline_params': True} model, not" in capsys.readouterr().err
