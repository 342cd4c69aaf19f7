"""Model-plane results back to the caller: a decoded curve (and its B-spline) at the caller's points or at a count
spaced as asked, through the caller's frame (geometry.adapt), checked for what float64 can hold."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from curve_vae.geometry import Frame, polyline_to_caller, spline_to_caller
from curve_vae.geometry.adapt import F32_MAX, joined_ends
from curve_vae.inference.errors import InputError
from curve_vae.inference.graphs import ModelGraphs
from curve_vae.inference.results import Curves, Spline


def to_caller(
    g: ModelGraphs,
    out: np.ndarray,
    frame: Frame | None,
    *,
    n_points: int | None,
    spacing: str = "parameter",
    fractions: np.ndarray | None = None,
    ctrl: np.ndarray | None = None,
    params: np.ndarray | None = None,
) -> tuple[np.ndarray, Spline | None]:
    """One model-plane result (n_points_model, 2) -> the caller's frame and length: `n_points` spaced as `spacing`
    says, else at the caller's positions (`fractions`), else the model's points. With the control points of a
    B-spline head (`ctrl`) the points are the spline's (at the head's learned `params` where it has them), and the
    spline comes back too."""
    if ctrl is None:
        curve = polyline_to_caller(
            out, frame, model_size=g.model_size, n_points=n_points, spacing=spacing, fractions=fractions
        )
        return curve, None
    curve, c, u = spline_to_caller(
        ctrl,
        frame,
        model_size=g.model_size,
        degree=g.spline_degree,
        model_points=g.n_points,
        n_points=n_points,
        spacing=spacing,
        fractions=fractions,
        model_params=params,
    )
    assert g.knots is not None
    return curve, Spline(c, g.knots, g.spline_degree, u)


def decoded_to_caller(
    g: ModelGraphs,
    out: np.ndarray,
    ctrl: np.ndarray | None,
    params: np.ndarray | None,
    *,
    frames: Sequence[Frame | None] | None,
    n_points: int | None,
    spacing: str,
    field: str = "latents",
) -> Curves:
    """Decoded curves (B, n_points_model, 2) (and control points, parameters) -> the caller's frames and length,
    checked; `field` names what a non-finite result is blamed on."""
    with np.errstate(all="ignore"):
        check_finite(out, field, "decodes to non-finite coordinates: the latent is far outside the training range")
        placed = [
            to_caller(
                g,
                o,
                frames[i] if frames else None,
                n_points=n_points,
                spacing=spacing,
                ctrl=None if ctrl is None else ctrl[i],
                params=None if params is None else params[i],
            )
            for i, o in enumerate(out)
        ]
    curves = np.stack([c for c, _ in placed]) if placed else np.zeros((0, n_points or g.n_points, 2))
    check_finite(curves, "frames" if frames else field, "the result does not fit in float64")
    splines = [s for _, s in placed] if g.has_splines else None
    return Curves(curves, list(frames) if frames else [None] * len(curves), splines)  # type: ignore[arg-type]


def joined(out: np.ndarray, ctrl: np.ndarray | None) -> tuple[np.ndarray, np.ndarray | None]:
    """A decoded curve (and its control points) closed: the ends joined at their midpoint (geometry.joined_ends), on
    the control points where there are some (a clamped B-spline's end points are its end control points)."""
    return (joined_ends(out), None) if ctrl is None else (out, joined_ends(ctrl))


def check_finite(a: np.ndarray, field: str, msg: str) -> None:
    bad = ~np.isfinite(a).reshape(len(a), -1).all(axis=1)
    if bad.any():
        raise InputError((field, int(np.argmax(bad))), msg)


def check_range(a: np.ndarray, field: str) -> None:
    bad = ~(np.abs(a) <= F32_MAX).reshape(len(a), -1).all(axis=1)
    if bad.any():
        raise InputError((field, int(np.argmax(bad))), "values beyond float32 range")
