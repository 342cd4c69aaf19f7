"""training/export.py: a VAE into the service's ONNX graphs and manifest. Export is quiet, switches the model to
eval, records the head's placement and the reading the model was trained for, and what it writes is served as it is."""

import gc
import warnings

import numpy as np
import pytest
import torch
from fastapi.testclient import TestClient

from curve_vae.geometry import random_control_points, resample, sample_bspline
from curve_vae.inference.reading import Reading
from curve_vae.inference.runtime import CurveRuntime
from curve_vae.service.app import create_app
from curve_vae.service.settings import Settings
from curve_vae.training.data import DataConfig
from curve_vae.training.export import export, model_size_of, reading_of, spline_manifest
from curve_vae.training.model import VAE, ModelConfig


def test_export_of_a_model_left_in_training_mode_is_quiet_and_exports_eval_graphs(tmp_path, capfd):
    torch.manual_seed(0)
    model = VAE(ModelConfig(spline_ctrl=31))  # left in training mode on purpose: export must switch it
    gc.collect()  # a file another test left in a reference cycle is reported now, not inside the export below
    gc.disable()  # (the export's own leaks would still show: CPython closes an unreferenced file at once)
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            export(model, tmp_path / "m", model_size=100.0, weights=False)
    finally:
        gc.enable()
    assert [str(w.message) for w in caught] == []
    err = capfd.readouterr().err
    assert "torchvision" not in err and "training mode" not in err, err
    assert not model.training


def test_the_live_schema_takes_the_latent_length_of_the_loaded_model(tmp_path):
    torch.manual_seed(0)
    export(VAE(ModelConfig(latent_dim=8)).eval(), tmp_path, model_size=100.0, weights=False)
    runtime = CurveRuntime.load(tmp_path, providers="cpu")
    with TestClient(create_app(Settings(model_dir=tmp_path), runtime=runtime)) as client:
        latents = client.get("/openapi.json").json()["components"]["schemas"]["DecodeRequest"]["properties"]["latents"]
        assert latents["items"]["minItems"] == latents["items"]["maxItems"] == 8
        assert client.post("/decode", json={"latents": [[0.0] * 8]}).status_code == 200


def test_an_exported_head_is_placed_closest_unless_asked_otherwise(tmp_path):
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


def test_a_refused_placement_writes_nothing(tmp_path):
    with pytest.raises(ValueError, match="placement must be one of"):
        export(VAE(ModelConfig(variant="cnn1")), tmp_path / "bad", model_size=92.6, placement="nearest")
    assert not (tmp_path / "bad").exists()


def test_the_model_size_is_the_median_of_the_larger_bounding_box_sides():
    boxes = [(10.0, 4.0), (2.0, 30.0), (7.0, 7.0), (50.0, 1.0), (3.0, 20.0)]  # larger sides 10, 30, 7, 50, 20
    curves = np.stack([[[5.0, 5.0], [5.0 + w, 5.0 + h], [5.0 + w / 2, 5.0]] for w, h in boxes])
    assert model_size_of(curves) == 20.0


@pytest.mark.parametrize(
    "config,reading",
    [
        pytest.param(DataConfig(), ("search", "search"), id="paper-mix-searched"),
        pytest.param(DataConfig(mix="broad", mix_version=3), ("search", "search"), id="broad-v3-searched"),
        pytest.param(DataConfig(mix="broad", mix_version=4), ("canonical", "parameter"), id="broad-v4-canonical"),
    ],
)
def test_the_reading_a_model_expects_follows_the_pose_of_its_mix(config, reading):
    assert reading_of(config) == reading


def test_the_spline_section_names_the_knots_and_where_each_point_sits():
    assert spline_manifest(ModelConfig()) is None  # no head, no section
    even = spline_manifest(ModelConfig(spline_ctrl=10), "index")
    assert even["n_ctrl"] == 10 and even["degree"] == 3 and even["placement"] == "index"
    # 10 control points of a clamped cubic: 10 + 3 + 1 knots, 4 repeated at each end, 10 - 3 = 7 even spans between
    assert even["knots"] == pytest.approx([0, 0, 0, 0, *(np.arange(1, 7) / 7), 1, 1, 1, 1])
    assert "u = i/160" in even["params"] and "learned_params" not in even
    learned = spline_manifest(ModelConfig(spline_ctrl=10, spline_params=True))
    assert learned["learned_params"] is True and "decoder's output params" in learned["params"]
    assert learned["placement"] == "closest"
