"""training/parts.py: a learned part exported beside a model's graphs and named in its manifest, which the runtime's
own check of the files then accepts; the numpy weights of models before 0.14.0 are read only when they name the kind
of network asked for."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import onnxruntime as ort
import pytest
import torch
from torch import nn

from curve_vae.errors import InvalidInput
from curve_vae.inference.model.manifest import Manifest, file_sha256
from curve_vae.training.parts import read_weights, write_part


def test_the_graph_and_its_entry_are_written_and_the_rest_of_the_manifest_kept(tmp_path: Path, model_dir: Path):
    model = tmp_path / "model"
    shutil.copytree(model_dir, model)
    before = json.loads((model / "manifest.json").read_text())
    torch.manual_seed(0)
    net = nn.Conv1d(3, 1, 3, padding=1).eval()
    path = write_part(
        model,
        "spacer",
        "net-v1",
        net,
        torch.zeros(2, 3, 8),
        {"note": "n", "held_out": {"rms": 0.1}},
        changes={"version": "7.0.0"},
    )
    assert path == model / "spacer.onnx"
    x = np.random.default_rng(0).normal(size=(5, 3, 8)).astype(np.float32)  # any batch
    with torch.no_grad():
        expected = net(torch.from_numpy(x)).numpy()
    got = ort.InferenceSession(str(path), providers=["CPUExecutionProvider"]).run(None, {"inputs": x})[0]
    np.testing.assert_allclose(got, expected, atol=1e-6)
    after = json.loads((model / "manifest.json").read_text())
    assert after["spacer"] == {"file": "spacer.onnx", "kind": "net-v1", "note": "n", "held_out": {"rms": 0.1}}
    assert after["files"]["spacer.onnx"] == {"sha256": file_sha256(path), "bytes": path.stat().st_size}
    assert after["version"] == "7.0.0"
    assert {k: v for k, v in after.items() if k not in ("spacer", "files", "version")} == {
        k: v for k, v in before.items() if k not in ("files", "version")
    }
    assert Manifest.read(model).spacer is not None


def test_the_arrays_come_back_without_their_kind(tmp_path: Path):
    np.savez(tmp_path / "w.npz", kind="net-v1", a_w=np.arange(6.0).reshape(2, 3), dilations=np.array([1, 2]))
    got = read_weights(tmp_path / "w.npz", "net-v1", "a test net")
    assert set(got) == {"a_w", "dilations"}
    np.testing.assert_array_equal(got["a_w"], np.arange(6.0).reshape(2, 3))


@pytest.mark.parametrize(("saved", "found"), [({"kind": "net-v2"}, "'net-v2'"), ({}, "''")])
def test_another_kind_or_none_is_refused_by_name(tmp_path: Path, saved, found):
    np.savez(tmp_path / "w.npz", a_w=np.zeros(3), **saved)
    with pytest.raises(InvalidInput, match=f"w.npz: a test net of kind {found}; this runtime reads 'net-v1'"):
        read_weights(tmp_path / "w.npz", "net-v1", "a test net")
