"""training/parts.py: a learned part's weights written beside a model's graphs and named in its manifest, which the
runtime's own check of the files then accepts."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np

from curve_vae.inference.manifest import Manifest, file_sha256
from curve_vae.inference.weights import read_weights
from curve_vae.training.parts import write_part


def test_the_weights_and_their_entry_are_written_and_the_rest_of_the_manifest_kept(tmp_path: Path, model_dir: Path):
    model = tmp_path / "model"
    shutil.copytree(model_dir, model)
    before = json.loads((model / "manifest.json").read_text())
    weights = {"a_w": np.ones((2, 3), np.float32), "dilations": np.array([1, 2])}
    path = write_part(
        model, "spacer", "net-v1", weights, {"note": "n", "held_out": {"rms": 0.1}}, changes={"version": "7.0.0"}
    )
    assert path == model / "spacer.npz"
    np.testing.assert_array_equal(read_weights(path, "net-v1", "a part")["a_w"], weights["a_w"])
    after = json.loads((model / "manifest.json").read_text())
    assert after["spacer"] == {"file": "spacer.npz", "kind": "net-v1", "note": "n", "held_out": {"rms": 0.1}}
    assert after["files"]["spacer.npz"] == {"sha256": file_sha256(path), "bytes": path.stat().st_size}
    assert after["version"] == "7.0.0"
    assert {k: v for k, v in after.items() if k not in ("spacer", "files", "version")} == {
        k: v for k, v in before.items() if k not in ("files", "version")
    }
    assert Manifest.read(model).spacer is not None
