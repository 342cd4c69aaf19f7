"""inference.model.opening: a model directory opened into the runtime's parts, and every file beside the graphs that
cannot
serve (a prior or a ranker that is not one, a prior of another latent size, an unknown placement) refused as a
ModelLoadError or an input error that names the file and the reason."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pytest

from curve_vae.errors import InvalidInput
from curve_vae.inference.generation.prior import LatentPrior
from curve_vae.inference.model.manifest import ModelLoadError, file_entry
from curve_vae.inference.model.opening import open_model
from curve_vae.inference.model.sessions import SessionConfig
from curve_vae.inference.runtime import CurveRuntime

OPTIONS = {
    "providers": "cpu",
    "batch_size": 8,
    "warm_up": False,
    "sessions": SessionConfig(intra_op_threads=1),
    "placement": "model",
    "cache_bytes": 0,
    "priors_dir": None,
}


def _replace_file(src: Path, out: Path, name: str, write) -> Path:
    """A copy of a model directory whose file `name` is rewritten by `write(path)`, its manifest's sha256 updated (so
    the manifest's own check passes and the file's content is what is tested)."""
    shutil.copytree(src, out)
    write(out / name)
    manifest = json.loads((out / "manifest.json").read_text())
    manifest["files"][name] = file_entry(out / name).model_dump()
    (out / "manifest.json").write_text(json.dumps(manifest))
    return out


def test_the_parts_are_the_directorys_and_make_a_runtime(model_dir):
    parts = open_model(model_dir, **OPTIONS)
    assert set(parts) == {"graphs", "prior", "closest", "cache", "model_dir", "priors", "ranker", "spacer"}
    on_disk = LatentPrior.load(model_dir / "prior.npz")
    np.testing.assert_array_equal(parts["prior"].means, on_disk.means)
    assert parts["ranker"] is None and parts["spacer"] is None and parts["cache"] is None and parts["priors"] == {}
    assert parts["closest"] is None  # "model": as the manifest's spline.placement says
    assert open_model(model_dir, **{**OPTIONS, "placement": "index", "cache_bytes": 1 << 20})["closest"] is False
    runtime = CurveRuntime(**parts)
    assert runtime.latent_dim == parts["graphs"].latent_dim == on_disk.latent_dim


def test_a_prior_that_is_not_one_names_its_file(model_dir, tmp_path):
    bad = _replace_file(model_dir, tmp_path / "m", "prior.npz", lambda p: p.write_bytes(b"not an npz at all"))
    with pytest.raises(ModelLoadError, match=r"prior\.npz: not a usable latent prior"):
        open_model(bad, **OPTIONS)


def test_a_prior_of_another_latent_size_is_refused(model_dir, tmp_path):
    def smaller(path: Path) -> None:
        prior = LatentPrior.load(path)
        k = prior.means.shape[0]
        LatentPrior(prior.weights, np.zeros((k, 8)), np.tile(np.eye(8), (k, 1, 1))).save(path)

    bad = _replace_file(model_dir, tmp_path / "m", "prior.npz", smaller)
    with pytest.raises(ModelLoadError, match="the prior has 8 latent dimensions, the model 32"):
        open_model(bad, **OPTIONS)


@pytest.mark.parametrize(
    ("part", "kind", "message"),
    [
        pytest.param(
            "ranker", "conv1d-ranker", r"not a usable reading ranker \(onnxruntime cannot open it", id="ranker"
        ),
        pytest.param(
            "spacer",
            "dilated-conv1d-cumsoftmax-v1",
            r"not a usable spacing guesser \(onnxruntime cannot open it",
            id="spacer",
        ),
    ],
)
def test_a_learned_part_that_is_not_one_names_its_file(model_dir, tmp_path, part, kind, message):
    bad = _replace_file(model_dir, tmp_path / "m", f"{part}.onnx", lambda path: path.write_bytes(b"not a graph"))
    manifest = json.loads((bad / "manifest.json").read_text())
    manifest[part] = {"file": f"{part}.onnx", "kind": kind}
    (bad / "manifest.json").write_text(json.dumps(manifest))
    with pytest.raises(ModelLoadError, match=rf"{part}\.onnx: {message}"):
        open_model(bad, **OPTIONS)


@pytest.mark.parametrize(
    ("placement", "error", "message"),
    [
        pytest.param("nearest", InvalidInput, "placement must be one of model, closest, index", id="unknown"),
        pytest.param("closest", ModelLoadError, "placement closest needs a model with a B-spline head", id="no-head"),
    ],
)
def test_a_placement_the_model_cannot_take_is_refused(raw_model_dir, placement, error, message):
    with pytest.raises(error, match=message):
        open_model(raw_model_dir, **{**OPTIONS, "placement": placement})
