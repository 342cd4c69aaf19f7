"""Model selection's numbers: each validation curve reconstructed from its latent mean and measured, point by point
(paper eq. 4) or each point to its closest point on the decoded spline (match "closest" and "twin")."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import torch
from torch import nn

from curve_vae.geometry import mse_per_curve
from curve_vae.training.losses import closest_point_terms

__all__ = ["reconstruct", "validation_closest", "validation_measure", "validation_mse"]


@torch.no_grad()
def reconstruct(
    model: nn.Module, curves: np.ndarray | torch.Tensor, *, batch: int = 1000, device: torch.device | None = None
) -> np.ndarray:
    """Decode the latent mean of each curve (paper: reconstruction at inference), float32."""
    device = device or next(model.parameters()).device
    model.eval()
    x = torch.as_tensor(curves, dtype=torch.float32)
    out = [model(x[i : i + batch].to(device))[0].float().cpu() for i in range(0, len(x), batch)]
    return torch.cat(out).numpy()


def validation_mse(model: nn.Module, curves: np.ndarray | torch.Tensor, *, device: torch.device | None = None) -> float:
    """Paper eq. 4 averaged over `curves`, reconstructing from the latent mean (model selection's number)."""
    target = curves.numpy() if isinstance(curves, torch.Tensor) else np.asarray(curves)
    return float(mse_per_curve(target, reconstruct(model, target, device=device)).mean())


@torch.no_grad()
def validation_closest(
    model: nn.Module, curves: np.ndarray | torch.Tensor, *, batch: int = 250, device: torch.device | None = None
) -> float:
    """Match "closest"'s model-selection number: each point's squared distance to its closest point on the spline
    decoded from the curve's latent mean, averaged as eq. 4 (`closest_point_terms`' mse)."""
    device = device or next(model.parameters()).device
    model.eval()
    x = torch.as_tensor(curves, dtype=torch.float32)
    total = 0.0
    for i in range(0, len(x), batch):
        part = x[i : i + batch].to(device)
        total += float(closest_point_terms(part, model(part, dense=True)[0])["mse"]) * len(part)
    return total / max(1, len(x))


def validation_measure(match: str) -> Callable[..., float]:
    """The validation number of a run trained with `match` (TrainConfig.match): eq. 4 for "index", else each point
    to its closest point on the decoded spline (what those runs train, and how the service places their points)."""
    return validation_mse if match == "index" else validation_closest
