"""A learned part written beside a model's graphs (the reading ranker, the spacing guesser): its network exported as
an ONNX graph (which the runtime runs in onnxruntime, releasing the GIL), and its entry in the manifest with its
`kind` and how it was trained and measured — both written atomically."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np
import torch
from torch import nn

from curve_vae.errors import InvalidInput
from curve_vae.files import atomic_write_text
from curve_vae.inference.model.manifest import file_sha256
from curve_vae.training.export import export_graph


def write_part(
    model_dir: str | Path,
    name: str,
    kind: str,
    net: nn.Module,
    example: torch.Tensor,
    entry: dict[str, Any],
    *,
    changes: dict[str, Any] | None = None,
) -> Path:
    """`net` exported as `name`.onnx in `model_dir` (input "inputs" shaped as `example`, any batch; output
    "outputs"), named in its manifest under `name` (file, kind, then `entry`) with its sha256; `changes`: other
    manifest fields set at once (version, reading). Returns its path."""
    root = Path(model_dir)
    path = root / f"{name}.onnx"
    export_graph(net, example, path, "inputs", ["outputs"])
    manifest_path = root / "manifest.json"
    manifest = json.loads(manifest_path.read_text())
    old = manifest.get(name, {}).get("file")
    if old and old != path.name:  # a part converted from its numpy weights: the old file is no longer the model's
        manifest["files"].pop(old, None)
    manifest["files"][path.name] = {"sha256": file_sha256(path), "bytes": path.stat().st_size}
    manifest[name] = {"file": path.name, "kind": kind, **entry}
    manifest.update(changes or {})
    atomic_write_text(manifest_path, json.dumps(manifest, indent=2) + "\n")
    return path


def read_weights(path: str | Path, kind: str, what: str) -> dict[str, np.ndarray]:
    """The arrays of an .npz of weights (how models before 0.14.0 shipped their ranker and guesser) whose `kind` is
    `kind` (else InvalidInput naming both; `what` names the part, "a reading ranker"), without the kind itself."""
    with np.load(path) as d:
        found = str(d["kind"]) if "kind" in d else ""
        if found != kind:
            raise InvalidInput(f"{path}: {what} of kind {found!r}; this runtime reads {kind!r}")
        return {k: d[k] for k in d.files if k != "kind"}
