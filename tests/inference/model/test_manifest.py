"""inference.model.manifest: the model-file contract, read, checked and written as one typed Manifest."""

from __future__ import annotations

import json
import shutil

import pytest

from curve_vae.inference.model.manifest import Manifest, ModelLoadError
from tests.helpers import SHIPPED


def test_the_shipped_manifests_read_and_round_trip(tmp_path):
    for src in (SHIPPED, SHIPPED / "paper"):
        m = Manifest.read(src)
        assert m.n_points == 161 and m.latent_dim == 32 and m.spline is not None and m.prior is not None
        m.write(tmp_path)
        again = json.loads((tmp_path / "manifest.json").read_text())
        original = json.loads((src / "manifest.json").read_text())
        for key in ("name", "version", "files", "graphs", "frame", "model_config", "training", "metrics"):
            assert again[key] == original[key], key  # fields the types know, and those they only carry


@pytest.mark.parametrize(
    "change, message",
    [
        pytest.param(lambda m: m.pop("n_points"), r"n_points: Field required", id="missing-dims"),
        pytest.param(lambda m: m.update(latent_dim=0), r"latent_dim: Input should be greater", id="no-latent"),
        pytest.param(lambda m: m["frame"].update(model_size=-1), r"model_size: Value error", id="bad-size"),
        pytest.param(
            lambda m: m["spline"].update(placement="nearest"),
            r"placement must be one of closest, index",
            id="placement",
        ),
        pytest.param(lambda m: m.update(reading={"pose": "sideways"}), r"reading.pose", id="reading"),
    ],
)
def test_a_bad_manifest_is_a_load_error_naming_the_field(model_dir, tmp_path, change, message):
    copy = tmp_path / "m"
    shutil.copytree(model_dir, copy)
    manifest = json.loads((copy / "manifest.json").read_text())
    change(manifest)
    (copy / "manifest.json").write_text(json.dumps(manifest))
    with pytest.raises(ModelLoadError, match=message):
        Manifest.read(copy)


def test_a_model_exported_before_readings_were_recorded_reads_with_the_search(model_dir):
    m = Manifest.read(model_dir)
    assert (m.reading.pose, m.reading.spacing) == ("search", "search")
