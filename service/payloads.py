"""JSON bodies of the generating and design endpoints, shared by the REST routes and the offline CLI.

`curve-vae sample|augment|fit` write exactly what POST /sample, /augment and /fit answer
for the same request, because both build their bodies here from the runtime's arrays.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from geometry import Frame, fit_bspline
from service.runtime import InputError, curve_metrics


def frames_json(frames: Sequence[Frame | None]) -> list[dict[str, Any]] | None:
    """Frames as the API reports them; None for frame "model"."""
    if not frames or frames[0] is None:
        return None
    return [{"center": list(f.center), "size": f.size} for f in frames if f is not None]


def with_metrics(body: dict[str, Any], curves: Sequence[np.ndarray], wanted: bool) -> dict[str, Any]:
    """`body` plus the per-curve quality measures when the request asked for them."""
    return {**body, "metrics": curve_metrics(curves)} if wanted else body


def sample_body(latents: np.ndarray, curves: np.ndarray, seed: int, *, metrics: bool = False) -> dict[str, Any]:
    return with_metrics({"latents": latents.tolist(), "curves": curves.tolist(), "seed": seed}, curves, metrics)


def augment_body(
    curves: np.ndarray,
    sources: np.ndarray,
    weights: np.ndarray,
    frames: Sequence[Frame | None],
    *,
    seed: int,
    offset: int,
    metrics: bool = False,
) -> dict[str, Any]:
    body = {
        "curves": curves.tolist(),
        "sources": sources.tolist(),
        "weights": weights.tolist(),
        "frames": frames_json(frames),
        "seed": seed,
        "offset": offset,
    }
    return with_metrics(body, curves, metrics)


def fit_body(
    curves: Sequence[np.ndarray], n_ctrl: int = 10, *, param: str = "chord", n_points: int | None = None
) -> dict[str, Any]:
    """Least-squares cubic B-spline of each curve (geometry.fit_bspline); InputError names a curve it cannot fit."""
    fits = []
    for i, c in enumerate(curves):
        if len(c) < n_ctrl:
            raise InputError(
                ("curves", i), f"n_ctrl={n_ctrl} control points need at least as many points, got {len(c)}"
            )
        try:
            with np.errstate(all="ignore"):
                f = fit_bspline(c, n_ctrl, param=param)
        except (ValueError, np.linalg.LinAlgError) as e:
            raise InputError(("curves", i), _unfittable(n_ctrl, e)) from e
        if not (np.isfinite(f.control_points).all() and np.isfinite([f.rms_error, f.max_error]).all()):
            raise InputError(("curves", i), _unfittable(n_ctrl))
        out: dict[str, Any] = {
            "control_points": f.control_points.tolist(),
            "knots": f.knots.tolist(),
            "degree": f.degree,
            "rms_error": f.rms_error,
            "max_error": f.max_error,
        }
        if n_points is not None:
            out["curve"] = f.evaluate(n_points).tolist()
        fits.append(out)
    return {"fits": fits}


def _unfittable(n_ctrl: int, error: Exception | None = None) -> str:
    why = f" ({error})" if error is not None and len(str(error)) < 120 else ""
    return (
        f"no unique least-squares spline with {n_ctrl} control points{why}: some knot span holds too few of the "
        'curve\'s points; use fewer control points, more points, or param "uniform"'
    )
