"""Export says nothing a user cannot act on: no training-mode warning, no torchvision lines, no FutureWarning."""

import warnings

import torch

from curve_vae.training.export import export
from curve_vae.training.model import VAE, ModelConfig


def test_export_of_a_model_left_in_training_mode_is_quiet_and_exports_eval_graphs(tmp_path, capfd):
    torch.manual_seed(0)
    model = VAE(ModelConfig(spline_ctrl=31))  # left in training mode on purpose: export must switch it
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        export(model, tmp_path / "m", model_size=100.0, weights=False)
    assert [str(w.message) for w in caught] == []
    err = capfd.readouterr().err
    assert "torchvision" not in err and "training mode" not in err, err
    assert not model.training
