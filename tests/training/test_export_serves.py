"""A model exported by training is served as it is: the live schema takes the exported latent length."""

import torch
from fastapi.testclient import TestClient

from curve_vae.service.app import create_app
from curve_vae.service.runtime import CurveRuntime
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
