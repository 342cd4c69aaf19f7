"""The model-file contract on the serving side: an exported model directory is a manifest, graphs and a prior,
each with its sha256 in the manifest; nothing is served that does not match. Also which onnxruntime providers
to run them on. Torch-free: `curve-vae triton` and the service read models through here.
"""

from __future__ import annotations

import hashlib
import json
import math
from pathlib import Path
from typing import Any

import onnxruntime as ort

from curve_vae.geometry.frame import MODEL_CENTER
from curve_vae.inference.prior import PRIOR_FILE

CUDA, CPU = "CUDAExecutionProvider", "CPUExecutionProvider"


class ModelLoadError(RuntimeError):
    """The model directory or the providers cannot serve: raised at startup, never per request."""


def file_sha256(path: Path) -> str:
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def read_manifest(model_dir: str | Path) -> dict[str, Any]:
    """manifest.json of an exported model, after checking the fields and graph checksums the service uses."""
    root = Path(model_dir)
    path = root / "manifest.json"
    if not path.is_file():
        raise ModelLoadError(
            f"no model in {root}: {path.name} is missing (export one with training/export.py, "
            "or point --model-dir / CURVE_VAE_MODEL_DIR at a directory holding encoder.onnx, "
            "decoder.onnx and manifest.json)"
        )
    try:
        manifest = json.loads(path.read_text())
        n_points, latent_dim = int(manifest["n_points"]), int(manifest["latent_dim"])
        model_size = float(manifest["frame"]["model_size"])
        files = manifest["files"]
    except (ValueError, KeyError, TypeError) as e:
        raise ModelLoadError(f"{path}: not a usable manifest ({type(e).__name__}: {e})") from e
    if n_points < 4 or latent_dim < 1 or not (math.isfinite(model_size) and model_size > 0):
        raise ModelLoadError(
            f"{path}: implausible n_points={n_points}, latent_dim={latent_dim}, model_size={model_size}"
        )
    center = manifest["frame"].get("center", list(MODEL_CENTER))
    if [float(v) for v in center] != list(MODEL_CENTER):  # frames map to this centre (geometry.frame)
        raise ModelLoadError(
            f"{path}: the model's plane is centred at {center}, but the service maps curves to {list(MODEL_CENTER)}; "
            "export the model with the paper's plane (ModelConfig.center 64)"
        )
    names = [graph_file(manifest, graph) for graph in ("encoder", "decoder")]
    if manifest.get("prior"):
        names.append(str(manifest["prior"].get("file", PRIOR_FILE)))
    for name in names:
        file = root / name
        if not file.is_file():
            raise ModelLoadError(f"{file} is missing (listed in {path})")
        expected = (files.get(name) or {}).get("sha256")
        if not expected:
            raise ModelLoadError(f"{path} carries no sha256 for {name}")
        actual = file_sha256(file)
        if actual != expected:
            raise ModelLoadError(
                f"{file}: sha256 {actual} does not match the manifest's {expected}; "
                "the file was changed or truncated after export: re-export the model or restore the file"
            )
    return manifest


def graph_file(manifest: dict[str, Any], graph: str) -> str:
    return str(manifest.get("graphs", {}).get(graph, {}).get("file", f"{graph}.onnx"))


def resolve_providers(choice: str) -> list[str]:
    """onnxruntime provider list for "cpu", "cuda" or "auto"; "cuda" fails loudly when unavailable."""
    available = ort.get_available_providers()
    if choice == "cpu":
        return [CPU]
    if choice == "cuda":
        if CUDA not in available:
            raise ModelLoadError(
                f"providers=cuda, but this onnxruntime ({ort.__version__}) offers only {available}: "
                "install the GPU build (pip install 'curve-vae[gpu]', i.e. onnxruntime-gpu, in place of "
                "onnxruntime) with CUDA 12 and cuDNN 9 libraries, or run with --providers cpu or auto"
            )
        return [CUDA, CPU]  # CPU takes any node CUDA has no kernel for
    if choice == "auto":
        return [CUDA, CPU] if CUDA in available else [CPU]
    raise ModelLoadError(f"providers must be cpu, cuda or auto, got {choice!r}")
