"""Checkpoint files: what a training run saves (last.pt, best.pt, epoch-NNNN.pt) and the shipped weights (vae.pt).

Two formats, one owner:

- a *training checkpoint* holds the weights with everything a run needs to resume or be exported: model,
  data and training configurations, optimiser, schedule, RNG state and the run's state (`version` CHECKPOINT_VERSION);
  snapshots and averaged checkpoints hold the same without optimiser, schedule and RNG.
- the *shipped weights* (`vae.pt` beside the ONNX graphs) hold the model configuration and weights only
  (`format` WEIGHTS_FORMAT, `version` WEIGHTS_VERSION); files written before it had a version (0.8.0 and older)
  hold the same two keys and are read as version 0.

Every reader goes through `load_checkpoint` (a training checkpoint, version checked) or `load_weights`
(either kind: what fine-tuning, evaluation and export start from). All are read with `weights_only=True`:
no pickled code runs on load. Writes are atomic: a crash never leaves half a file behind.
"""

from __future__ import annotations

import json
from dataclasses import asdict
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import torch

from curve_vae.errors import InvalidInput
from curve_vae.files import atomic_path
from curve_vae.training.config import ModelConfig
from curve_vae.training.model import VAE

if TYPE_CHECKING:
    from curve_vae.training.data import DataConfig

CHECKPOINT_VERSION = 1
WEIGHTS_FORMAT = "curve-vae weights"
WEIGHTS_VERSION = 1
#: what a snapshot or a shipped file leaves out of a training checkpoint
RESUME_ONLY = ("optimizer", "scheduler", "rng")


def atomic_save(obj: Any, path: str | Path) -> None:
    """torch.save through a temporary file, renamed over `path` once complete."""
    with atomic_path(path) as tmp:
        torch.save(obj, tmp)


def _read(path: str | Path) -> dict[str, Any]:
    try:
        obj = torch.load(path, map_location="cpu", weights_only=True)
    except FileNotFoundError:
        raise
    except Exception as e:  # a truncated file, another program's pickle, …
        raise InvalidInput(f"{path}: not a curve-vae checkpoint ({type(e).__name__}: {e})") from e
    if not isinstance(obj, dict) or "model_config" not in obj or "model" not in obj:
        raise InvalidInput(f"{path}: not a curve-vae checkpoint (no model_config and model in it)")
    return obj


def load_checkpoint(path: str | Path) -> dict[str, Any]:
    """A training checkpoint (last.pt, best.pt, a snapshot or an average), its version checked."""
    ckpt = _read(path)
    if ckpt.get("format") == WEIGHTS_FORMAT or "version" not in ckpt:
        raise InvalidInput(
            f"{path}: shipped weights (vae.pt), not a training checkpoint; start a run from it with --init-from"
        )
    if ckpt["version"] != CHECKPOINT_VERSION:
        raise InvalidInput(f"{path}: checkpoint version {ckpt['version']}, expected {CHECKPOINT_VERSION}")
    return ckpt


def load_weights(path: str | Path) -> tuple[ModelConfig, dict[str, torch.Tensor]]:
    """The model configuration and weights of a training checkpoint or of shipped weights (vae.pt)."""
    ckpt = _read(path)
    if ckpt.get("format") == WEIGHTS_FORMAT:
        if ckpt.get("version", 0) > WEIGHTS_VERSION:
            raise InvalidInput(
                f"{path}: weights version {ckpt['version']}, newer than this curve-vae reads ({WEIGHTS_VERSION})"
            )
    elif "version" in ckpt and ckpt["version"] != CHECKPOINT_VERSION:
        raise InvalidInput(f"{path}: checkpoint version {ckpt['version']}, expected {CHECKPOINT_VERSION}")
    return ModelConfig(**ckpt["model_config"]), ckpt["model"]


def widen(weights: dict[str, torch.Tensor], model: VAE) -> dict[str, torch.Tensor]:
    """Weights of a model without learned spline parameters, for `model` with them: the decoder's last layer gains
    its parameter channel with zero weights, which decodes the same curves at the same even parameters."""
    layer = len(model.decoder.features) - 1
    out = dict(weights)
    for name in (f"decoder.features.{layer}.weight", f"decoder.features.{layer}.bias"):
        w = weights[name]
        pad = torch.zeros_like(w.narrow(-1 if w.dim() == 1 else 1, 0, 1))
        out[name] = torch.cat([w, pad], dim=0 if w.dim() == 1 else 1)
    return out


def model_from_checkpoint(path: str | Path) -> VAE:
    """The model of a training checkpoint or of shipped weights, rebuilt from its stored configuration, in eval mode."""
    cfg, state = load_weights(path)
    model = VAE(cfg)
    model.load_state_dict(state)
    return model.eval()


def save_weights(model: VAE, path: str | Path) -> None:
    """The shipped weights file: model configuration and weights, versioned."""
    atomic_save(
        {
            "format": WEIGHTS_FORMAT,
            "version": WEIGHTS_VERSION,
            "model_config": asdict(model.cfg),
            "model": model.state_dict(),
        },
        path,
    )


def without_resume_state(ckpt: dict[str, Any]) -> dict[str, Any]:
    """A training checkpoint less its optimiser, schedule and RNG state: a snapshot (a third of the size)."""
    return {k: v for k, v in ckpt.items() if k not in RESUME_ONLY}


def keep_snapshot(run_dir: Path, ckpt: dict[str, Any], epoch: int, keep: int) -> None:
    """Save this epoch's weights (no optimiser state) and drop snapshots older than the latest `keep`."""
    atomic_save(without_resume_state(ckpt), run_dir / f"epoch-{epoch:04d}.pt")
    for old in sorted(run_dir.glob("epoch-[0-9][0-9][0-9][0-9].pt"))[:-keep]:
        old.unlink()


def rng_state(gen: np.random.Generator) -> dict[str, Any]:
    return {"torch": torch.get_rng_state(), "numpy": json.dumps(gen.bit_generator.state)}


def check_resumed_data(last: Path, data_cfg: DataConfig, resume: bool) -> None:
    """On resume, refuse to go on from `last` on other data than it was trained on (another mix version, size or
    seed), before any data is drawn."""
    if not resume or not last.exists():
        return
    stored = dict(load_checkpoint(last).get("data_config") or {})
    stored.setdefault("mix_version", 1 if stored.get("mix") == "broad" else 0)  # written before mix versions
    asked = asdict(data_cfg)
    differ = {k: (stored[k], v) for k, v in asked.items() if k in stored and stored[k] != v}
    if differ:
        said = ", ".join(f"{k} {old!r} (run) vs {new!r} (asked)" for k, (old, new) in differ.items())
        raise InvalidInput(
            f"{last} was trained on other data: {said}; resume it with the same data options "
            "(e.g. --mix-version, --n-train, --data-seed), or start a new run directory (--init-from for its weights)"
        )
