"""Checkpoint files: one reader for training checkpoints and shipped weights, versions checked, bad files named."""

import pytest
import torch

from curve_vae.training.checkpoint import (
    CHECKPOINT_VERSION,
    WEIGHTS_FORMAT,
    load_checkpoint,
    load_weights,
    model_from_checkpoint,
    save_weights,
    without_resume_state,
)
from curve_vae.training.config import ModelConfig
from curve_vae.training.model import VAE


@pytest.fixture(scope="module")
def model():
    return VAE(ModelConfig(latent_dim=4, spline_ctrl=10)).eval()


def test_shipped_weights_round_trip_with_their_format_and_version(tmp_path, model):
    save_weights(model, tmp_path / "vae.pt")
    raw = torch.load(tmp_path / "vae.pt", weights_only=True)
    assert raw["format"] == WEIGHTS_FORMAT and raw["version"] == 1
    cfg, state = load_weights(tmp_path / "vae.pt")
    assert cfg == model.cfg
    again = model_from_checkpoint(tmp_path / "vae.pt")
    x = torch.rand(3, 161, 2) * 128
    torch.testing.assert_close(again(x)[1], model(x)[1])  # the encoder's means: the same weights
    assert not again.training


def test_weights_written_before_versions_are_read(tmp_path, model):
    from dataclasses import asdict

    torch.save({"model_config": asdict(model.cfg), "model": model.state_dict()}, tmp_path / "old.pt")
    assert load_weights(tmp_path / "old.pt")[0] == model.cfg


def test_a_training_checkpoint_is_versioned_and_weights_are_not_one(tmp_path, model):
    from dataclasses import asdict

    ckpt = {
        "version": CHECKPOINT_VERSION,
        "model_config": asdict(model.cfg),
        "model": model.state_dict(),
        "optimizer": {},
    }
    torch.save(ckpt, tmp_path / "last.pt")
    assert load_checkpoint(tmp_path / "last.pt")["version"] == CHECKPOINT_VERSION
    assert "optimizer" not in without_resume_state(ckpt)
    torch.save({**ckpt, "version": 99}, tmp_path / "future.pt")
    with pytest.raises(ValueError, match="future.pt: checkpoint version 99, expected 1"):
        load_weights(tmp_path / "future.pt")
    save_weights(model, tmp_path / "vae.pt")
    with pytest.raises(ValueError, match="shipped weights .vae.pt., not a training checkpoint; .*--init-from"):
        load_checkpoint(tmp_path / "vae.pt")


def test_a_file_that_is_no_checkpoint_is_named(tmp_path):
    (tmp_path / "junk.pt").write_bytes(b"not a checkpoint")
    with pytest.raises(ValueError, match="junk.pt: not a curve-vae checkpoint"):
        load_weights(tmp_path / "junk.pt")
    torch.save({"something": 1}, tmp_path / "other.pt")
    with pytest.raises(ValueError, match="other.pt: not a curve-vae checkpoint .no model_config"):
        load_checkpoint(tmp_path / "other.pt")
