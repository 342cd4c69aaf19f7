"""Learned parts for tests: a ranker and a spacing guesser of random weights, as the numpy weights models before
0.14.0 shipped (ranker.npz, spacer.npz) and as the ONNX graphs they convert to, written into a copy of a model."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import torch

from curve_vae.inference.ranker import RANKER_KIND
from curve_vae.inference.spacer import GRID, SPACER_KIND
from curve_vae.training.parts import write_part
from curve_vae.training.ranker import RankerNet
from curve_vae.training.spacer import DILATIONS, MIX_AFTER, SpacerNet


def _drawn(shapes: dict[str, tuple[int, ...]], seed: int) -> dict[str, np.ndarray]:
    rng = np.random.default_rng(seed)
    out = {}
    for name, shape in shapes.items():
        out[f"{name}_w"] = (rng.normal(size=shape) / np.sqrt(np.prod(shape[1:]))).astype(np.float32)
        out[f"{name}_b"] = (0.1 * rng.normal(size=shape[0])).astype(np.float32)
    return out


def ranker_weights(seed: int = 0) -> dict[str, np.ndarray]:
    """Weights of RankerNet's shape, drawn at random, named as ranker.npz names them."""
    shapes = {"conv0": (32, 4, 5), "conv1": (64, 32, 5), "conv2": (96, 64, 5), "dense0": (96, 192), "dense1": (1, 96)}
    return _drawn(shapes, seed)


def spacer_weights(seed: int = 0) -> dict[str, np.ndarray]:
    """Weights of SpacerNet's shape, drawn at random, named as spacer.npz names them."""
    c = 32
    shapes = {"inp": (c, 3, 5), "mix": (c, c), "out": (1, c, 2)}
    for i, _ in enumerate(DILATIONS):
        shapes[f"block{i}_a"], shapes[f"block{i}_b"] = (c, c, 3), (c, c, 1)
    return {"dilations": np.array(DILATIONS), "mix_after": np.array(MIX_AFTER), **_drawn(shapes, seed)}


def save_npz(path: Path, kind: str, weights: dict[str, np.ndarray]) -> Path:
    np.savez(path, kind=kind, **weights)  # type: ignore[arg-type]
    return path


def with_ranker(src: Path, out: Path, weights: dict[str, np.ndarray], *, reading: bool = True) -> Path:
    """A copy of a model directory with a ranker of `weights` as its graph; reading: the manifest's reading becomes
    pose "learned" with spacing "search"."""
    shutil.copytree(src, out, dirs_exist_ok=True)
    n_points = json.loads((out / "manifest.json").read_text())["n_points"]
    changes = {"reading": {"pose": "learned", "spacing": "search"}} if reading else {}
    example = torch.zeros(2, 4, n_points)
    write_part(out, "ranker", RANKER_KIND, RankerNet.from_weights(weights).eval(), example, {}, changes=changes)
    return out


def with_spacer(src: Path, out: Path, weights: dict[str, np.ndarray]) -> Path:
    """A copy of a model directory with a spacing guesser of `weights` as its graph."""
    shutil.copytree(src, out, dirs_exist_ok=True)
    net = SpacerNet.from_weights(weights).eval()
    write_part(out, "spacer", SPACER_KIND, net, torch.zeros(2, 3, GRID), {})
    return out
