"""The VAE objective of the paper: MSE + β·KL + λ·Laplacian (eqs. 3–7), in pixel units, and the objectives that
measure shapes whatever the points' spacing (closest points, and mixed: index for curves at their own spacing)."""

from __future__ import annotations

import torch


def laplacian(curves: torch.Tensor) -> torch.Tensor:
    """Second difference p[i+1] − 2p[i] + p[i−1] along the points, (B, N, 2) → (B, N, 2).

    The two end points have no neighbour on one side; they take the value of the nearest
    interior point, as in the authors' reference code.
    """
    inner = curves[:, 2:] - 2 * curves[:, 1:-1] + curves[:, :-2]  # (B, N-2, 2)
    return torch.cat([inner[:, :1], inner, inner[:, -1:]], dim=1)


def kl_divergence(mean: torch.Tensor, log_var: torch.Tensor) -> torch.Tensor:
    """KL(N(μ, σ²) ‖ N(0, 1)) (paper eq. 5), averaged over batch and latent dimensions."""
    return torch.mean(-0.5 * (1 + log_var - mean.pow(2) - log_var.exp()))


def vae_loss(
    target: torch.Tensor,
    pred: torch.Tensor,
    mean: torch.Tensor,
    log_var: torch.Tensor,
    *,
    beta: float = 1e-3,
    lap_weight: float = 1.0,
) -> dict[str, torch.Tensor]:
    """Each term and their weighted sum ("loss"). Curves are (B, N, 2) in the 128×128 plane.

    mse: eq. 4, mean over points and coordinates; kl: eq. 5; lap: eq. 7 as a mean of
    |Lap(c) − Lap(ĉ)| over points and coordinates. Computed in float32 whatever the
    autocast dtype, since the MSE we aim for is ~1e-5 of the coordinates' square.
    """
    target, pred = target.float(), pred.float()
    mse = torch.mean((target - pred) ** 2)
    kl = kl_divergence(mean.float(), log_var.float())
    lap = torch.mean(torch.abs(laplacian(target) - laplacian(pred)))
    return {"loss": mse + beta * kl + lap_weight * lap, "mse": mse, "kl": kl, "lap": lap}


def squared_distance_to_polyline(points: torch.Tensor, line: torch.Tensor) -> torch.Tensor:
    """(B, P, 2) points, (B, L, 2) polyline → (B, P): each point's squared distance to the polyline, measured to the
    two segments on either side of its nearest vertex (the foot clamped to the segment). The nearest vertex is
    searched without gradient (a distance matrix); the distance to the segments carries it."""
    n_seg = line.shape[1] - 1
    with torch.no_grad():
        nearest = torch.cdist(points, line).argmin(dim=-1)  # (B, P)
    seg = torch.stack([nearest - 1, nearest], dim=-1).clamp(0, n_seg - 1).flatten(1)  # (B, 2P)
    index = seg.unsqueeze(-1).expand(-1, -1, 2)
    a = torch.gather(line, 1, index).view(*points.shape[:2], 2, 2)  # (B, P, 2 segments, 2)
    d = torch.gather(line, 1, index + 1).view(*points.shape[:2], 2, 2) - a
    p = points.unsqueeze(2)
    t = ((p - a) * d).sum(-1) / (d.square().sum(-1) + 1e-12)
    foot = a + t.clamp(0.0, 1.0).unsqueeze(-1) * d
    return (foot - p).square().sum(-1).amin(dim=-1)


def closest_point_terms(
    target: torch.Tensor, curve: torch.Tensor, *, per_curve: bool = False
) -> dict[str, torch.Tensor]:
    """How far a decoded curve is from the target's points, whatever their spacing along it. `curve` (B, M, 2) is the
    decoded spline sampled densely from its start to its end; target (B, N, 2).

    mse: each target point's squared distance to its closest point on the curve (the two end points to the curve's
    ends, which the service pins there), as eq. 4 averages it (over points and both coordinates); back: the same from
    the curve's samples to the target's polyline, which keeps the curve from straying where no point is. Means over
    the batch, or (B,) each curve's with per_curve."""
    target, curve = target.float(), curve.float()
    inner = squared_distance_to_polyline(target[:, 1:-1], curve)
    ends = torch.stack([(target[:, 0] - curve[:, 0]).square().sum(-1), (target[:, -1] - curve[:, -1]).square().sum(-1)])
    mse = (inner.sum(1) + ends.sum(0)) / (2 * target.shape[1])
    back = squared_distance_to_polyline(curve, target).mean(1) / 2
    return {"mse": mse, "back": back} if per_curve else {"mse": mse.mean(), "back": back.mean()}


def closest_loss(
    target: torch.Tensor, curve: torch.Tensor, mean: torch.Tensor, log_var: torch.Tensor, *, beta: float = 1e-3
) -> dict[str, torch.Tensor]:
    """The objective of match "closest": `closest_point_terms` both ways + β·KL; `curve` the dense decoding. Its
    "mse" is the one-way distance the service returns (each point to its closest point on the curve)."""
    terms = closest_point_terms(target, curve)
    kl = kl_divergence(mean.float(), log_var.float())
    lap = torch.zeros((), device=kl.device)  # the spline head is smooth; a Laplacian of unmatched points means nothing
    return {"loss": terms["mse"] + terms["back"] + beta * kl, **terms, "kl": kl, "lap": lap}


def mixed_loss(
    target: torch.Tensor,
    twin: torch.Tensor,
    curve: torch.Tensor,
    mean: torch.Tensor,
    log_var: torch.Tensor,
    *,
    beta: float = 1e-3,
    lap_weight: float = 1.0,
    stride: int = 2,
) -> dict[str, torch.Tensor]:
    """The objective of match "mixed": eq. 4 + λ·Laplacian for each curve drawn evenly in its own parameter (it equals
    its twin, (B, N, 2)), closest points both ways for every other curve, + β·KL. `curve` is the dense decoding, whose
    every `stride`-th sample is the decoded point i (VAE.forward(dense=True)). A curve drawn at another spacing is
    matched by its shape alone, so the decoder need not bend its spline to put even parameters at that spacing's
    points, and the paper's curves keep eq. 4's point-by-point target. "native" is the share of the batch matched by
    index."""
    target, curve = target.float(), curve.float()
    native = (target - twin.float()).square().sum(-1).amax(-1) < 1e-8  # (B,): drawn evenly in its own parameter
    pred = curve[:, ::stride]
    index_mse = (target - pred).square().mean((1, 2))
    lap = torch.abs(laplacian(target) - laplacian(pred)).mean((1, 2))
    close = closest_point_terms(target, curve, per_curve=True)
    zero = torch.zeros_like(index_mse)
    mse = torch.where(native, index_mse, close["mse"]).mean()
    lap = torch.where(native, lap, zero).mean()
    back = torch.where(native, zero, close["back"]).mean()
    kl = kl_divergence(mean.float(), log_var.float())
    return {
        "loss": mse + lap_weight * lap + back + beta * kl,
        "mse": mse,
        "back": back,
        "kl": kl,
        "lap": lap,
        "native": native.float().mean(),
    }
