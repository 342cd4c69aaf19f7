"""Weight averaging of checkpoints, with BatchNorm statistics recomputed for the average.

Late in a one-cycle schedule the weights wander around a minimum; their average sits
nearer its centre than any one of them (Izmailov et al. 2018, "Averaging Weights Leads to
Wider Optima"). The running BatchNorm statistics of the inputs do not average into the
statistics of the averaged network, so they are measured again by one pass over training
curves (torch.optim.swa_utils.update_bn, a cumulative mean rather than a momentum).
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
import torch
from torch import nn

from curve_vae.errors import InvalidInput
from curve_vae.training.checkpoint import CHECKPOINT_VERSION, load_checkpoint
from curve_vae.training.config import ModelConfig
from curve_vae.training.model import VAE
from curve_vae.training.validation import validation_measure

__all__ = ["average_state_dicts", "recompute_batchnorm", "average_checkpoints"]


def average_state_dicts(states: Sequence[dict[str, torch.Tensor]]) -> dict[str, torch.Tensor]:
    """Element-wise mean of floating-point entries; other entries (counters) from the last state."""
    if not states:
        raise InvalidInput("nothing to average: no state dicts given")
    keys = list(states[-1])
    for i, s in enumerate(states):
        if list(s) != keys or any(s[k].shape != states[-1][k].shape for k in keys):
            raise InvalidInput(f"state dict {i} has other entries than the last one: not the same architecture")
    out: dict[str, torch.Tensor] = {}
    for k in keys:
        ref = states[-1][k]
        if ref.is_floating_point():
            out[k] = torch.stack([s[k].to(torch.float64) for s in states]).mean(0).to(ref.dtype)
        else:
            out[k] = ref.clone()
    return out


@torch.no_grad()
def recompute_batchnorm(
    model: nn.Module, curves: np.ndarray | torch.Tensor, *, batch: int = 128, seed: int = 0
) -> None:
    """Set every BatchNorm's running mean/variance to their mean over `curves`, in training-mode batches.

    Batches of the training size reproduce the batch statistics the network was trained with;
    `seed` fixes the reparameterisation noise of the pass. The model is left in eval mode.
    """
    torch.manual_seed(seed)
    x = torch.as_tensor(curves, dtype=torch.float32)
    loader = [x[i : i + batch] for i in range(0, len(x) - batch + 1, batch)] or [x]
    torch.optim.swa_utils.update_bn(loader, model)
    model.eval()


def average_checkpoints(
    paths: Sequence[str | Path],
    *,
    train_curves: np.ndarray | None,
    val_curves: np.ndarray | None = None,
    bn_batch: int = 128,
    log=print,
) -> dict[str, Any]:
    """A checkpoint (training format) holding the mean weights of `paths`.

    train_curves: BatchNorm statistics are measured on these (None: keep the averaged
    running statistics). val_curves: report the validation MSE of each input and of the
    result (stored in the checkpoint's `averaged` record).
    """
    ckpts = [load_checkpoint(p) for p in paths]
    cfgs = {tuple(sorted(c["model_config"].items())) for c in ckpts}
    if len(cfgs) != 1:
        raise InvalidInput(f"the checkpoints hold different models: {[c['model_config'] for c in ckpts]}")
    model = VAE(ModelConfig(**ckpts[0]["model_config"]))
    validation_mse = validation_measure(ckpts[-1]["train_config"].get("match", "index"))  # the run's own measure
    record: dict[str, Any] = {"sources": [], "bn_curves": 0 if train_curves is None else len(train_curves)}
    for p, c in zip(paths, ckpts, strict=True):
        src: dict[str, Any] = {"path": str(p), "epoch": c["state"]["epoch"]}
        if val_curves is not None:
            model.load_state_dict(c["model"])
            src["val_mse"] = validation_mse(model.eval(), val_curves)
            log(f"{p} (epoch {src['epoch']}): validation MSE {src['val_mse']:.4f}")
        record["sources"].append(src)
    model.load_state_dict(average_state_dicts([c["model"] for c in ckpts]))
    model.eval()
    if val_curves is not None:
        record["val_mse_running_stats"] = validation_mse(model, val_curves)
        log(f"average, averaged BatchNorm statistics: validation MSE {record['val_mse_running_stats']:.4f}")
    if train_curves is not None:
        recompute_batchnorm(model, train_curves, batch=bn_batch)
        if val_curves is not None:
            record["val_mse"] = validation_mse(model, val_curves)
            log(
                f"average, BatchNorm statistics of {len(train_curves)} training curves: "
                f"validation MSE {record['val_mse']:.4f}"
            )
    elif val_curves is not None:
        record["val_mse"] = record["val_mse_running_stats"]
    last = ckpts[-1]
    return {
        "version": CHECKPOINT_VERSION,
        "model_config": last["model_config"],
        "data_config": last["data_config"],
        "train_config": last["train_config"],
        "model": model.state_dict(),
        "state": last["state"],
        "averaged": record,
    }
