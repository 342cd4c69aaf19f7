"""Where the error on arc-length-spaced curves comes from: the encoder, or the B-spline head's fixed parameters.

    .venv/bin/python scripts/spacing_limits.py --model-dir models --count 100 --steps 100

For the paper's test curves at parameter spacing and at arc-length spacing, brought to the model plane as the
service brings them (frame and pose "auto"), it prints the mean relative RMSE (RMSE ÷ bounding-box diagonal, in
the model plane):

- of the reconstruction as served (the encoder's latent mean, decoded);
- after refining each latent by gradient descent (Adam) on the decoder's squared error to the input, for
  `--steps` steps: the best any encoder could do with this decoder, approached from above;
- of the least-squares projection onto the head's clamped uniform cubic B-spline at its fixed, even parameters:
  the floor of the head itself, whatever the latent;
- of the reconstruction as served with its points slid along its own spline to the best parameters for each curve
  (Adam on per-curve parameter increments, as a head with learned parameters makes them: `free`, one per point;
  `smooth`, a warp of 12 increments interpolated): what such a head could gain with the decoder's curves unchanged.

A parameter-spaced paper curve lies exactly on such a spline (its floor is ~0); an arc-length-spaced one does not.
Needs torch (the decoder's gradients) and the model's vae.pt.
"""

from __future__ import annotations

import argparse
import time

import numpy as np
import torch

from curve_vae.geometry import resample
from curve_vae.geometry.bspline import evaluate_bspline, fit_bspline
from curve_vae.inference.runtime import CurveRuntime
from curve_vae.training.checkpoint import model_from_checkpoint
from curve_vae.training.model import bspline_basis, increments_to_params, last_span_mask
from curve_vae.training.suite import paper_test_split


def rel_rmse(pred: np.ndarray, target: np.ndarray) -> float:
    """Mean over curves of RMSE ÷ the target's bounding-box diagonal, in percent."""
    diag = np.hypot(*np.ptp(target, axis=1).T)
    return float(100 * (np.sqrt(((pred - target) ** 2).sum(-1).mean(-1)) / diag).mean())


def refine(decoder: torch.nn.Module, mean: np.ndarray, target: np.ndarray, steps: int) -> np.ndarray:
    """Decoded curves after `steps` Adam steps on each latent toward its target (model plane)."""
    z = torch.tensor(mean, dtype=torch.float32, requires_grad=True)
    x = torch.tensor(target, dtype=torch.float32)
    opt = torch.optim.Adam([z], lr=0.02)
    for _ in range(steps):
        opt.zero_grad()
        y, _ = decoder.decode(z, full=False)
        ((y - x) ** 2).sum(-1).mean().backward()
        opt.step()
    with torch.no_grad():
        return decoder.decode(z, full=False)[0].numpy()


def placed(ctrl: np.ndarray, target: np.ndarray, knots: np.ndarray, warp: int | None, steps: int) -> np.ndarray:
    """The splines `ctrl` (B, K, 2) at the increasing parameters that bring them closest to `target` (B, N, 2), found
    by Adam on per-curve softmax increments: one per point, or `warp` of them interpolated linearly."""
    c, x, t = (torch.tensor(a, dtype=torch.float64) for a in (ctrl, target, knots))
    closed, n = last_span_mask(t), target.shape[1] - 1
    logits = torch.zeros(len(x), 1, warp or n, dtype=torch.float64, requires_grad=True)
    opt = torch.optim.Adam([logits], lr=0.05)

    def curves() -> torch.Tensor:
        full = torch.nn.functional.interpolate(logits, size=n, mode="linear", align_corners=True) if warp else logits
        return torch.matmul(bspline_basis(increments_to_params(full[:, 0]), t, closed, 3), c)

    for _ in range(steps):
        opt.zero_grad()
        ((curves() - x) ** 2).sum(-1).mean().backward()
        opt.step()
    with torch.no_grad():
        return curves().numpy()


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--model-dir", default="models", help="model directory with vae.pt (default: models)")
    p.add_argument("--count", type=int, default=100, help="paper test curves (default: 100)")
    p.add_argument("--steps", type=int, default=100, help="latent refinement steps (default: 100)")
    a = p.parse_args()
    torch.set_num_threads(1)
    runtime = CurveRuntime.load(a.model_dir)
    decoder = model_from_checkpoint(f"{a.model_dir}/vae.pt").decoder
    n_ctrl = len(runtime.knots) - runtime.spline_degree - 1
    paper = [np.asarray(c, np.float64) for c in paper_test_split()[: a.count]]
    sets = {"parameter spacing": paper, "arc-length spacing": [resample(c, len(c)) for c in paper]}
    print(
        f"{'set':20s} {'as served':>10s} {f'refined ({a.steps})':>14s} {'head floor':>11s} "
        f"{'placed: free':>13s} {'smooth':>8s}"
    )
    for name, curves in sets.items():
        t = time.perf_counter()
        prep = runtime.prepare(curves)  # frame and pose "auto": the candidate the service keeps
        target = prep.model.astype(np.float64)
        served = rel_rmse(prep.decoded, target)
        refined = rel_rmse(refine(decoder, prep.mean, prep.model, a.steps), target)
        floor = rel_rmse(
            np.stack(
                [evaluate_bspline(fit_bspline(c, n_ctrl).control_points, np.linspace(0, 1, len(c))) for c in target]
            ),
            target,
        )
        ctrl, knots = prep.ctrl.astype(np.float64), np.asarray(runtime.knots)
        free, smooth = (rel_rmse(placed(ctrl, target, knots, warp, 300), target) for warp in (None, 12))
        print(
            f"{name:20s} {served:9.3f}% {refined:13.3f}% {floor:10.3f}% {free:12.3f}% {smooth:7.3f}%"
            f"   ({time.perf_counter() - t:.0f} s)"
        )


if __name__ == "__main__":
    main()
