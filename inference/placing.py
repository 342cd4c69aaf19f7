"""Model-plane results back to the caller: a decoded curve (and its B-spline) at the caller's points or at a count
spaced as asked, through the caller's frame (geometry.adapt), checked for what float64 can hold."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from curve_vae.geometry import Frame, mse_per_curve, polyline_to_caller, spline_to_caller
from curve_vae.geometry.adapt import F32_MAX, is_closed, joined_ends
from curve_vae.geometry.batch import FrameRows, Ragged
from curve_vae.geometry.bspline import spline_values
from curve_vae.inference.errors import InputError
from curve_vae.inference.graphs import ModelGraphs
from curve_vae.inference.prepared import Prepared
from curve_vae.inference.results import Curves, Spline, head_splines


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


def placed_to_caller(g: ModelGraphs, prep: Prepared) -> tuple[list[np.ndarray], list[Spline], np.ndarray] | None:
    """`to_caller` of every reconstruction at its caller's points at once, for a batch whose points were placed on
    their splines (`ReadCurve.feet`) in frames of their own: each curve's points, its spline in the caller's frame
    and its MSE (paper eq. 4) against the input; a closed input comes back closed. None where the batch is not of
    that kind (the caller's code then maps each curve by itself)."""
    rows = prep.rows
    if not rows or not prep.placed or any(r.frame is None or r.ctrl is None for r in rows):
        return None
    curves = Ragged.of(prep.inputs)
    starts, ends = curves.starts, curves.starts + curves.lengths - 1
    pts = curves.points
    extent = (np.maximum.reduceat(pts, starts) - np.minimum.reduceat(pts, starts)).max(axis=1)
    closed = np.abs(pts[ends] - pts[starts]).max(axis=1) <= 1e-9 * extent  # geometry.adapt.is_closed, per curve
    # every row has its frame, control points and feet (checked above): the `is not None`s only narrow the types
    ctrl = np.stack([r.ctrl for r in rows if r.ctrl is not None]).astype(np.float64)
    ctrl[closed] = joined_ends(ctrl[closed])  # a loop comes back a loop
    frames = FrameRows.of([r.frame for r in rows if r.frame is not None])
    feet = np.concatenate([r.feet for r in rows if r.feet is not None])
    model = spline_values(ctrl, feet, curves.owner, degree=g.spline_degree)[0]
    back = frames.from_model(Ragged(model, curves.lengths), g.model_size)
    n_ctrl = ctrl.shape[1]
    ctrl_back = frames.from_model(Ragged(ctrl.reshape(-1, 2), np.full(len(rows), n_ctrl)), g.model_size)
    reverse = frames.reverse[curves.owner]
    params = np.where(reverse, 1.0 - feet, feet)[curves.reversed_where(frames.reverse)]
    sq = ((pts - back) ** 2).sum(axis=1)
    mse = np.bincount(curves.owner, weights=sq, minlength=len(rows)) / (2 * curves.lengths)
    bad = ~(np.isfinite(mse) & np.isfinite(np.add.reduceat(np.abs(back).sum(axis=1), starts)))
    if bad.any():
        raise InputError(
            ("curves", int(np.argmax(bad))), "the reconstruction does not fit in float64: scale the curve down"
        )
    assert g.knots is not None
    splines = [
        Spline(c, g.knots, g.spline_degree, u)
        for c, u in zip(ctrl_back.reshape(len(rows), n_ctrl, 2), curves.split(params))
    ]
    return curves.split(back), splines, mse


def each_to_caller(
    g: ModelGraphs, prep: Prepared, *, n_points: int | None, spacing: str
) -> tuple[list[np.ndarray], list[Spline | None], np.ndarray]:
    """`placed_to_caller` curve by curve, for any batch: each reconstruction at its caller's points (or `n_points`
    spaced as `spacing` says), its spline and its MSE at the caller's own points; a closed input comes back closed."""
    results, splines, mse = [], [], np.empty(len(prep.rows))
    for i, (pts, row) in enumerate(zip(prep.inputs, prep.rows)):
        assert row.decoded is not None
        o, c, u = row.decoded, row.ctrl, row.params
        if is_closed(pts):  # a loop comes back a loop
            o, c = joined(o, c)
        # placed: the spline's points closest to the input's, at their parameters (not the head's)
        at, head = (row.fraction, u) if row.feet is None else (row.feet, None)
        own, spline = to_caller(g, o, row.frame, n_points=None, fractions=at, ctrl=c, params=head)
        mse[i] = mse_per_curve(pts[None], own[None])[0]
        if n_points is not None:
            own, spline = to_caller(g, o, row.frame, n_points=n_points, spacing=spacing, ctrl=c, params=u)
        if not (np.isfinite(own).all() and np.isfinite(mse[i])):
            raise InputError(("curves", i), "the reconstruction does not fit in float64: scale the curve down")
        results.append(own)
        splines.append(spline)
    return results, splines, mse


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
    splines = head_splines([s for _, s in placed], g.has_splines)
    own_frames: list[Frame | None] = list(frames) if frames else [None] * len(curves)
    return Curves(curves, own_frames, splines)


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


def closed_rows(out: np.ndarray, ctrl: np.ndarray | None) -> tuple[np.ndarray, np.ndarray | None]:
    """Decoded rows (and control points) each with its ends joined (placing.joined)."""
    rows = [joined(o, None if ctrl is None else ctrl[i]) for i, o in enumerate(out)]
    closed_out = np.stack([o for o, _ in rows]).astype(np.float32)
    return closed_out, None if ctrl is None else np.stack([c for _, c in rows if c is not None]).astype(np.float32)
