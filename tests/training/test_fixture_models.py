"""The service tests' committed models (tests/fixtures/) still compute what tests/fixtures/make_models.py makes."""

import importlib.util
import json
from pathlib import Path

import numpy as np
import onnxruntime as ort
import pytest

FIXTURES = Path(__file__).resolve().parents[1] / "fixtures"
spec = importlib.util.spec_from_file_location("make_models", FIXTURES / "make_models.py")
make_models = importlib.util.module_from_spec(spec)
spec.loader.exec_module(make_models)


def _run(model_dir: Path, curves: np.ndarray) -> list[np.ndarray]:
    enc = ort.InferenceSession(str(model_dir / "encoder.onnx"), providers=["CPUExecutionProvider"])
    dec = ort.InferenceSession(str(model_dir / "decoder.onnx"), providers=["CPUExecutionProvider"])
    mean, log_var = enc.run(["mean", "log_var"], {"curves": curves})
    return [mean, log_var, *dec.run(None, {"latent": mean})]


@pytest.mark.parametrize("name", sorted(make_models.MODELS))
def test_the_committed_fixture_is_what_the_script_makes(name, tmp_path):
    fresh = make_models.export_untrained(tmp_path, **make_models.MODELS[name])
    committed = FIXTURES / name
    curves = make_models.bspline_curves(8, seed=11).astype(np.float32)
    for a, b in zip(_run(committed, curves), _run(fresh, curves), strict=True):
        np.testing.assert_allclose(a, b, rtol=1e-5, atol=1e-5, err_msg=f"rewrite with: python {make_models.__file__}")
    with np.load(committed / "prior.npz") as c, np.load(fresh / "prior.npz") as f:
        for key in ("weights", "means", "cholesky"):
            np.testing.assert_allclose(c[key], f[key], rtol=1e-5, atol=1e-6)
    drop = ("created", "files", "exported_with")
    old, new = (json.loads((d / "manifest.json").read_text()) for d in (committed, fresh))
    assert {k: v for k, v in old.items() if k not in drop} == {k: v for k, v in new.items() if k not in drop}
