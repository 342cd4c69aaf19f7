"""A model exported by training is served as it is: the live schema takes the exported latent length."""

import torch
from fastapi.testclient import TestClient

from curve_vae.inference.reading import Reading
from curve_vae.inference.runtime import CurveRuntime
from curve_vae.service.app import create_app
from curve_vae.service.settings import Settings
from curve_vae.training.export import export
from curve_vae.training.model import VAE, ModelConfig


def test_the_live_schema_takes_the_latent_length_of_the_loaded_model(tmp_path):
    torch.manual_seed(0)
    export(VAE(ModelConfig(latent_dim=8)).eval(), tmp_path, model_size=100.0, weights=False)
    runtime = CurveRuntime.load(tmp_path, providers="cpu")
    with TestClient(create_app(Settings(model_dir=tmp_path), runtime=runtime)) as client:
        latents = client.get("/openapi.json").json()["components"]["schemas"]["DecodeRequest"]["properties"]["latents"]
        assert latents["items"]["minItems"] == latents["items"]["maxItems"] == 8
        assert client.post("/decode", json={"latents": [[0.0] * 8]}).status_code == 200


def test_an_exported_head_is_placed_closest_unless_asked_otherwise(tmp_path):
    import numpy as np
    import pytest

    from curve_vae.geometry import random_control_points, resample, sample_bspline

    torch.manual_seed(0)
    model = VAE(ModelConfig(variant="cnn1", spline_ctrl=31)).eval()
    curves = [resample(c, 80) for c in sample_bspline(random_control_points(np.random.default_rng(0), 3), 161)]
    errors = {}
    for placement in ("closest", "index"):
        export(model, tmp_path / placement, model_size=92.6, weights=False, placement=placement)
        runtime = CurveRuntime.load(tmp_path / placement, providers="cpu")
        assert runtime.manifest.spline.placement == placement
        assert runtime.closest_placement == (placement == "closest")
        errors[placement] = runtime.reconstruct(curves, Reading(pose="as_is")).mse
    assert np.all(errors["closest"] <= errors["index"] * (1 + 1e-9)) and np.any(errors["closest"] < errors["index"])
    default = export(model, tmp_path / "default", model_size=92.6, weights=False)
    assert default.spline.placement == "closest"
    with pytest.raises(ValueError, match="placement must be one of"):
        export(model, tmp_path / "bad", model_size=92.6, weights=False, placement="nearest")
