"""Export a trained VAE as two single-file ONNX graphs and a manifest (the service's input).

encoder.onnx: curves (B, n_points, 2) in the 128×128 plane → mean, log_var (B, latent_dim)
decoder.onnx: latent (B, latent_dim) → curves (B, n_points, 2) in the 128×128 plane, and with a
    B-spline head also control_points (B, n_ctrl, 2): curves = basis @ control_points
manifest.json: names, dims, sha256 of each file, the frame convention, config and metrics.
"""

from __future__ import annotations

import json
import logging
import platform
import time
import warnings
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import asdict
from pathlib import Path
from typing import Any

import numpy as np
import torch
from torch import nn

from curve_vae.files import atomic_path, atomic_write_text
from curve_vae.geometry import clamped_uniform_knots
from curve_vae.service.model_files import file_sha256
from curve_vae.service.prior import PRIOR_FILE, LatentPrior
from curve_vae.training.checkpoint import save_weights
from curve_vae.training.model import VAE, ModelConfig

MANIFEST_VERSION = 1
OPSET = 18


class _EncoderGraph(nn.Module):
    def __init__(self, vae: VAE) -> None:
        super().__init__()
        self.encoder = vae.encoder

    def forward(self, curves: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
        return self.encoder(curves)


class _DecoderGraph(nn.Module):
    """The decoder at inference; with a B-spline head it also returns the control points."""

    def __init__(self, vae: VAE) -> None:
        super().__init__()
        self.decoder = vae.decoder

    def forward(self, latent: torch.Tensor) -> torch.Tensor | tuple[torch.Tensor, torch.Tensor]:
        curves, ctrl = self.decoder.decode(latent)
        return curves if ctrl is None else (curves, ctrl)


def spline_manifest(cfg: ModelConfig) -> dict[str, Any] | None:
    """How the decoder's control points make its curves, for consumers of the graph."""
    if not cfg.spline_ctrl:
        return None
    return {
        "n_ctrl": cfg.spline_ctrl,
        "degree": 3,
        "knots": clamped_uniform_knots(cfg.spline_ctrl, 3).tolist(),
        "params": f"curve point i is the clamped uniform cubic B-spline at u = i/{cfg.n_points - 1}",
        "output": "control_points",
    }


def sha256(path: str | Path) -> str:
    """The checksum the manifest records and the service checks (one definition: service.model_files)."""
    return file_sha256(Path(path))


@contextmanager
def _quiet_exporter() -> Iterator[None]:
    """Silence what the exporter says that no user can act on: torchvision being absent (its detection ops are not
    used here) and a deprecation inside torch's own pytree code. Real problems still raise."""
    registry = logging.getLogger("torch.onnx._internal.exporter._registration")
    level = registry.level
    registry.setLevel(logging.ERROR)
    try:
        with warnings.catch_warnings():
            warnings.filterwarnings("ignore", message=r".*isinstance\(treespec, LeafSpec\).*", category=FutureWarning)
            yield
    finally:
        registry.setLevel(level)


def _export(module: nn.Module, example: torch.Tensor, path: Path, in_name: str, out_names: list[str]) -> None:
    batch = torch.export.Dim("batch", min=1, max=1 << 20)
    module = module.eval()  # inference graphs: BatchNorm on its running statistics
    with atomic_path(path) as tmp, _quiet_exporter():
        program = torch.onnx.export(
            module,
            (example,),
            dynamo=True,
            input_names=[in_name],
            output_names=out_names,
            dynamic_shapes=({0: batch},),
            opset_version=OPSET,
            external_data=False,
            verbose=False,
        )
        program.save(str(tmp), external_data=False)


def model_size_of(curves: np.ndarray) -> float:
    """The bounding-box size (larger side) the model is used to: median over the data set.

    Curves in the caller's frame are scaled to this size before encoding (frame "auto").
    """
    ext = curves.max(axis=1) - curves.min(axis=1)  # (N, 2)
    return float(np.median(ext.max(axis=1)))


def export(
    model: VAE,
    out_dir: str | Path,
    *,
    name: str = "curve-vae",
    version: str = "0.0.0",
    model_size: float,
    extra: dict[str, Any] | None = None,
    weights: bool = True,
    prior: LatentPrior | None = None,
    prior_info: dict[str, Any] | None = None,
) -> dict[str, Any]:
    """Write encoder.onnx, decoder.onnx, (vae.pt, prior.npz) and manifest.json into out_dir; return the manifest.

    prior: the learned latent distribution (training/prior.py) the service samples from; prior_info
    says how it was fitted.
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    model = model.float().cpu().eval()
    cfg = model.cfg
    _export(
        _EncoderGraph(model),
        torch.zeros(2, cfg.n_points, 2) + 64.0,
        out / "encoder.onnx",
        "curves",
        ["mean", "log_var"],
    )
    dec_outputs = ["curves", "control_points"] if cfg.spline_ctrl else ["curves"]
    _export(_DecoderGraph(model), torch.zeros(2, cfg.latent_dim), out / "decoder.onnx", "latent", dec_outputs)
    files = ["encoder.onnx", "decoder.onnx"]
    if prior is not None:
        prior.save(out / PRIOR_FILE)
        files.append(PRIOR_FILE)
    if weights:
        save_weights(model, out / "vae.pt")
        files.append("vae.pt")
    manifest = {
        "manifest_version": MANIFEST_VERSION,
        "name": name,
        "version": version,
        "created": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()),
        "variant": cfg.variant,
        "n_points": cfg.n_points,
        "latent_dim": cfg.latent_dim,
        "files": {f: {"sha256": sha256(out / f), "bytes": (out / f).stat().st_size} for f in files},
        "graphs": {
            "encoder": {
                "file": "encoder.onnx",
                "inputs": {"curves": ["batch", cfg.n_points, 2]},
                "outputs": {"mean": ["batch", cfg.latent_dim], "log_var": ["batch", cfg.latent_dim]},
            },
            "decoder": {
                "file": "decoder.onnx",
                "inputs": {"latent": ["batch", cfg.latent_dim]},
                "outputs": {
                    "curves": ["batch", cfg.n_points, 2],
                    **({"control_points": ["batch", cfg.spline_ctrl, 2]} if cfg.spline_ctrl else {}),
                },
            },
        },
        **({"spline": spline_manifest(cfg)} if cfg.spline_ctrl else {}),
        **(
            {
                "prior": {
                    "file": PRIOR_FILE,
                    "kind": "gaussian_mixture",
                    "components": len(prior.weights),
                    **(prior_info or {}),
                }
            }
            if prior is not None
            else {}
        ),
        "frame": {
            "plane": [128.0, 128.0],
            "center": [cfg.center, cfg.center],
            "model_size": model_size,
            "normalisation": f"inside the graphs: (x - {cfg.center}) / {cfg.scale}; I/O in plane pixels",
            "sampling": f"{cfg.n_points} points evenly spaced in the B-spline parameter",
        },
        "model_config": asdict(cfg),
        "opset": OPSET,
        "exported_with": {"torch": torch.__version__, "python": platform.python_version()},
        **(extra or {}),
    }
    atomic_write_text(out / "manifest.json", json.dumps(manifest, indent=2) + "\n")
    return manifest
