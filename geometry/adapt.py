"""Frame and length adaptation: a caller's curve to the model's plane and point count, and a result back.

The model takes `n_points` points (161) in its 128×128 plane. `to_model_plane` brings a caller's
curve there — through its `Frame` when it has one (frame.py), then to `n_points` points: along the
point index with spacing "parameter" (the caller's own spacing kept, so a curve of `n_points`
passes untouched),
evenly by arc length with "arc_length", at even steps of the parameters of the cubic B-spline that fits it
closest with "natural" (`natural.natural_params`: a spacing the paper's curves could have, whatever the
caller's) — and
says where each of the caller's points sits along
the result. `polyline_to_caller` and `spline_to_caller` bring a model-plane result back: at those
positions, or at any count spaced as asked, mapped through the frame. From a B-spline head's
control points the points are the spline's at the returned parameters, and the control points
and parameters come back in the caller's frame and point order: a similarity maps a spline's
points as it maps its control points.

Pure numpy: the service's runtime (inference/runtime.py) calls these around its ONNX sessions.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from curve_vae.errors import InvalidInput
from curve_vae.geometry.bspline import arc_length_params, evaluate_bspline, sample_bspline
from curve_vae.geometry.frame import Frame, arc_fractions, at_fractions, resample
from curve_vae.geometry.natural import natural_params

#: Largest float32: the graphs' input type, so the bound of a model-plane coordinate.
F32_MAX = float(np.finfo(np.float32).max)


class BeyondFloat32(InvalidInput):
    """A curve whose model-plane points are not finite float32 numbers (its frame's scale under- or overflows, or
    its own coordinates are that large)."""


def is_closed(points: np.ndarray) -> bool:
    """Whether a curve (n, 2) ends where it starts (to 1e-9 of its extent): a loop listed with its first point
    repeated at the end, as closed airfoil coordinate files are."""
    pts = np.asarray(points, np.float64)
    return bool(np.abs(pts[-1] - pts[0]).max() <= 1e-9 * np.ptp(pts, axis=0).max())


#: What a curve whose points all coincide is told, wherever curves are read (the request schema, a .npy body, the
#: reader): `COINCIDENT.format(n=points)`.
COINCIDENT = "all {n} points coincide: a curve needs at least 2 distinct points"


def coincident(curves: Sequence[Any]) -> np.ndarray:
    """(B,) whether each curve's points (n_i, 2) all coincide: no curve to read."""
    return np.array([bool((np.asarray(c) == np.asarray(c)[:1]).all()) for c in curves], bool)


def joined_ends(points: np.ndarray) -> np.ndarray:
    """A copy of points or control points, (n, 2) or a batch (..., n, 2), whose first and last rows are both their
    mean: the reconstruction of a closed curve closed again (for a clamped B-spline, its end control points are its
    end points)."""
    out = np.array(points, np.float64)
    out[..., 0, :] = out[..., -1, :] = (out[..., 0, :] + out[..., -1, :]) / 2
    return out


def to_model_plane(
    points: np.ndarray,
    frame: Frame | None,
    *,
    model_size: float,
    n_points: int,
    spacing: str = "parameter",
    natural: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray | None]:
    """One caller curve (n, 2) -> its model-plane points (n_points, 2) and where its own points sit along them.

    frame None: the points are in the model plane already. The second value is the fraction in [0, 1] of the
    model's points at which each of the caller's points sits (for `polyline_to_caller`); None when the model's
    points are the caller's. spacing "natural": the curve read at even steps of its points' `natural_params`
    (`natural`, computed here when not given; they do not depend on the frame). Raises BeyondFloat32 where a
    model-plane coordinate does not fit in float32.
    """
    pts = np.asarray(points, np.float64)
    m = frame.to_model(pts, model_size) if frame is not None else pts
    fractions = None
    if spacing == "natural":
        fractions = natural_params(pts) if natural is None else np.asarray(natural, np.float64)
        if frame is not None and frame.reverse:  # m lists the points the other way round: so do their parameters
            fractions = (1.0 - fractions)[::-1]
        at = fractions + np.arange(len(fractions)) * 1e-12  # strictly increasing, for np.interp
        grid = np.linspace(0.0, 1.0, n_points)
        m = np.stack([np.interp(grid, at, m[:, 0]), np.interp(grid, at, m[:, 1])], axis=1)
    elif spacing == "arc_length":
        fractions = arc_fractions(m)
        m = resample(m, n_points)
    elif len(pts) != n_points:
        fractions = np.linspace(0.0, 1.0, len(pts))
        m = resample(m, n_points, spacing=spacing)
    if not (np.abs(m) <= F32_MAX).all():  # also false for inf and nan
        raise BeyondFloat32("model-plane coordinates beyond float32 range")
    return m, fractions


def polyline_to_caller(
    out: np.ndarray,
    frame: Frame | None,
    *,
    model_size: float,
    n_points: int | None = None,
    spacing: str = "parameter",
    fractions: np.ndarray | None = None,
) -> np.ndarray:
    """A model-plane result (m, 2) -> the caller's frame and length, interpolated along the polyline.

    n_points given: that many points, spaced as `spacing` says (with "parameter" and m points, the result's own).
    Otherwise at `fractions` of its index range (the caller's positions from `to_model_plane`), or its points as
    they are. frame None: left in the model plane.
    """
    curve = np.asarray(out, np.float64)
    if n_points is not None:  # a returned curve's spacing: by arc length, or the result's own for every other reading
        curve = resample(curve, n_points, spacing="arc_length" if spacing == "arc_length" else "parameter")
    elif fractions is not None:
        curve = at_fractions(curve, fractions)
    return frame.from_model(curve, model_size) if frame is not None else curve


def spline_params(
    control_points: np.ndarray,
    *,
    degree: int,
    model_points: int,
    n_points: int | None = None,
    spacing: str = "parameter",
    fractions: np.ndarray | None = None,
    model_params: np.ndarray | None = None,
) -> np.ndarray | None:
    """The parameters at which `spline_to_caller` evaluates a model-plane spline (see there); None: evenly in the
    parameter, n_points or model_points of them."""
    count = n_points or model_points
    if n_points is not None and spacing == "arc_length":
        return arc_length_params(np.asarray(control_points, np.float64), n_points, degree=degree)
    if model_params is not None:
        own = np.linspace(0.0, 1.0, len(model_params))
        at = (
            np.asarray(fractions, np.float64)
            if n_points is None and fractions is not None
            else np.linspace(0, 1, count)
        )
        return np.clip(np.interp(at, own, np.asarray(model_params, np.float64)), 0.0, 1.0)
    if n_points is None and fractions is not None:
        return np.clip(np.asarray(fractions, np.float64), 0.0, 1.0)
    return None


def spline_to_caller(
    control_points: np.ndarray,
    frame: Frame | None,
    *,
    model_size: float,
    degree: int,
    model_points: int,
    n_points: int | None = None,
    spacing: str = "parameter",
    fractions: np.ndarray | None = None,
    model_params: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A model-plane clamped uniform B-spline (n_ctrl, 2) -> its points, control points and the points' parameters
    in the caller's frame and order.

    The points are the spline's exactly, at parameters: n_points of them, at the model's spacing or (spacing
    "arc_length") evenly in arc length; else at `fractions` (the caller's positions along the model's points);
    else the model's own `model_points`. The model's spacing: its points' parameters `model_params` (a head that
    learns them), interpolated between points; without them, evenly in the parameter.
    """
    c = np.asarray(control_points, np.float64)
    count = n_points or model_points
    u = spline_params(
        c,
        degree=degree,
        model_points=model_points,
        n_points=n_points,
        spacing=spacing,
        fractions=fractions,
        model_params=model_params,
    )
    if u is None:  # evenly in the parameter: the basis is the same for every curve (cached by sample_bspline)
        curve, u = sample_bspline(c, count, degree), np.linspace(0.0, 1.0, count)
    else:
        curve = evaluate_bspline(c, u, degree)
    if frame is not None:  # a similarity maps a spline's points as it maps its control points
        curve, c = frame.from_model(curve, model_size), frame.from_model(c, model_size)
        u = frame.to_caller_params(u)
    return curve, c, u
