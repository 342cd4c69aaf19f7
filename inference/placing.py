"""Model-plane results back to the caller: a decoded curve (and its B-spline) at the caller's points or at a count
spaced as asked, through the caller's frame (geometry.adapt), checked for what float64 can hold; its ends kept where
its inputs' are, and untangled where it crosses itself and its input does not. Three sections: placing, ends,
valid shapes."""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from typing import Protocol

import numpy as np

from curve_vae.geometry import Frame, mse_per_curve, ordered_closest_params, polyline_to_caller, spline_to_caller
from curve_vae.geometry.adapt import F32_MAX, is_closed, joined_ends
from curve_vae.geometry.batch import FrameRows, Ragged
from curve_vae.geometry.bspline import spline_values
from curve_vae.geometry.ends import pinned_ends
from curve_vae.geometry.validity import crosses, new_crossings, untangled
from curve_vae.inference.errors import InputError
from curve_vae.inference.model.graphs import ModelGraphs
from curve_vae.inference.prepared import Prepared, ReadCurve
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


def model_targets(inputs: Sequence[np.ndarray], frames: Sequence[Frame | None], model_size: float) -> list[np.ndarray]:
    """Each caller curve in the model plane, through its frame: all at once where every curve has one (the points a
    decoded spline is placed against)."""
    given = [f for f in frames if f is not None]
    if frames and len(given) == len(frames):  # every curve has a frame
        curves = Ragged.of(list(inputs))
        return curves.split(FrameRows.of(given).to_model(curves, model_size))
    return [f.to_model(p, model_size) if f is not None else p for f, p in zip(frames, inputs)]


def placed_again(
    inputs: Sequence[np.ndarray], rows: list[ReadCurve], *, model_size: float, degree: int
) -> list[ReadCurve]:
    """Rows placed on their splines (closest placement), each caller point placed again on its spline as it is now
    (its ends moved, below)."""
    have = [i for i, r in enumerate(rows) if r.feet is not None and r.ctrl is not None]
    if not have:
        return rows
    ctrl = np.stack([rows[i].ctrl for i in have])  # type: ignore[misc]
    targets = model_targets([inputs[i] for i in have], [rows[i].frame for i in have], model_size)
    with np.errstate(all="ignore"):
        feet, err = ordered_closest_params(ctrl, targets, degree=degree)
    out = list(rows)
    for k, i in enumerate(have):
        out[i] = dataclasses.replace(rows[i], feet=feet[k], distance=float(err[k]))
    return out


# Answers that keep their inputs' ends (geometry.ends): a reconstruction starts and ends where its input does, an
# in-between at the weighted blend of its inputs' matching ends, so an end the inputs share is shared by every curve
# between them; a closed input's answer closes at its input's closing point.
#
# Ends match as the set is read, in one pose: each input's end at the model's parameter 0 (its first point, or its last
# where its pose reverses it) with the others' there. Blends are taken in the caller's plane, where the inputs are.
#

#: geometry.ends' reach per move for a reconstruction, whose end is a few thousandths of its size off: the end control
#: point alone moves, which reads closest (the users' sets 0.95–1.00× of not moving it; 4: 0.97–1.02×, 8: 0.98–1.08×).
READ_REACH = 1.0
#: The same for an in-between (besides the share of its ends' own moves it carries), whose end may be a few hundredths
#: off: a longer fade, so its end shifts rather than hooks (docs/figures/ends.png).
MIX_REACH = 8.0


def model_order_ends(inputs: Sequence[np.ndarray], frames: Sequence[Frame | None]) -> np.ndarray:
    """(B, 2, 2) each input's two end points, in the caller's plane, in the model's order: the point at the model's
    parameter 0 first."""
    out = np.stack([np.stack([p[0], p[-1]]) for p in inputs]) if len(inputs) else np.zeros((0, 2, 2))
    reverse = np.array([f is not None and f.reverse for f in frames], bool)
    out[reverse] = out[reverse, ::-1]
    return out


def to_model_ends(ends: np.ndarray, frames: Sequence[Frame | None], model_size: float) -> np.ndarray:
    """(B, 2, 2) model-order end points in the caller's plane -> the model plane, through each curve's frame (none:
    already there)."""
    out = np.array(ends, np.float64)
    have = np.array([f is not None for f in frames], bool)
    if have.any():
        rows = FrameRows.of([f for f in frames if f is not None])
        listed = out[have]  # in the order to_model_rows reverses back for a reversed frame
        listed[rows.reverse] = listed[rows.reverse, ::-1]
        out[have] = rows.to_model_rows(listed, model_size)
    return out


def pinned_rows(
    inputs: Sequence[np.ndarray], rows: Sequence[ReadCurve], *, model_size: float, degree: int
) -> list[ReadCurve]:
    """Each decoded row with control points moved onto its input's ends (a closed input's: its closing point at both);
    rows without control points as they are. Points placed on the spline are to be placed again (Reader)."""
    out = list(rows)
    have = [i for i, r in enumerate(rows) if r.ctrl is not None]
    if not have:
        return out
    ends = to_model_ends(
        model_order_ends([inputs[i] for i in have], [rows[i].frame for i in have]),
        [rows[i].frame for i in have],
        model_size,
    )
    for b, i in enumerate(have):
        if is_closed(inputs[i]):
            ends[b, 1] = ends[b, 0]
    before = np.stack([np.asarray(rows[i].ctrl, np.float64) for i in have])
    ctrl = pinned_ends(before, ends[:, 0], ends[:, 1], degree=degree, per_move=READ_REACH)
    for b, i in enumerate(have):
        out[i] = dataclasses.replace(rows[i], ctrl=ctrl[b], pin=ctrl[b] - before[b])
    return out


def pinned_mixes(
    ctrl: np.ndarray,
    inputs: Sequence[np.ndarray],
    in_frames: Sequence[Frame | None],
    weights: np.ndarray,
    out_frames: Sequence[Frame | None],
    *,
    model_size: float,
    degree: int,
) -> np.ndarray:
    """In-betweens' control points (rows, n_ctrl, 2), each moved onto the blend (its weight row) of the inputs'
    matching ends, in the caller's plane, then into its own frame (already there for a row that carries its ends'
    own moves in full: a row [1, 0] is its first end's answer)."""
    # row by row, never a matrix product: BLAS sums in an order that depends on the number of rows, and a curve must
    # not change with the batch or page it is made in
    w = np.asarray(weights, np.float64)
    ends = (w[:, :, None, None] * model_order_ends(inputs, in_frames)[None]).sum(axis=1)  # (rows, 2, 2)
    model = to_model_ends(ends, out_frames, model_size)
    return pinned_ends(ctrl, model[:, 0], model[:, 1], degree=degree, per_move=MIX_REACH)


# Answers that are valid shapes: a reconstruction or an in-between that crosses itself where its input does not is
# untangled (geometry.validity.untangled) before it is returned, and says so.
#
# A reconstruction placed on its spline (a B-spline head, closest placement or refine: the shipped model's) is the
# spline at its points' parameters; where it crosses itself and its input does not, the control points around the
# crossing are refitted to the input's own points. The change of control points is kept with the row
# (`ReadCurve.repair`), so that curves mixed from it carry it in proportion: an in-between's control points get the
# weighted sum of its ends' repairs, and a row [1, 0] is its first end's answer to the bit. An in-between that still
# crosses is refitted the same way near its crossings, to the blend of its ends' answers at its points (what the
# point-wise blend of two valid, similar shapes is: valid where they are alike).
#


class _Indexed(Protocol):
    def __getitem__(self, k: int) -> np.ndarray: ...


def untangle_rows(
    inputs: Sequence[np.ndarray],
    rows: Sequence[ReadCurve],
    *,
    model_size: float,
    degree: int,
    free_ends: bool = False,
) -> tuple[list[ReadCurve], list[int]]:
    """The rows whose answers (their splines at their points' parameters) cross themselves where the inputs do not,
    untangled against the inputs' own points, their ends held (and, with `free_ends`, where that fails, free to
    move: a valid answer before kept ends); the rest as they are; and which rows still cross after it. Rows without
    a spline or placed points (a model without a B-spline head or closest placement) are returned as they are."""
    out = list(rows)
    tangled: list[int] = []
    placed = [i for i, r in enumerate(rows) if r.ctrl is not None and r.feet is not None]
    if not placed:
        return out, tangled
    ctrl = [_closed_ctrl(inputs[i], rows[i]) for i in placed]
    feet = [np.asarray(rows[i].feet, np.float64) for i in placed]
    lengths = np.array([len(f) for f in feet])
    owner = np.repeat(np.arange(len(placed)), lengths)
    answers = np.split(
        spline_values(np.stack(ctrl), np.concatenate(feet), owner, degree=degree)[0], np.cumsum(lengths)[:-1]
    )
    bad = np.flatnonzero(new_crossings([inputs[i] for i in placed], answers))
    for j in bad:
        i = placed[j]
        row = rows[i]
        target = row.frame.to_model(inputs[i], model_size) if row.frame is not None else np.asarray(inputs[i])
        closed = is_closed(inputs[i])
        fixed = ctrl[j]
        # the ends held (kept where the input's are), then, as the last resort, free to move: a valid answer first
        for ends in (False, True) if free_ends else (False,):
            fixed, _ = untangled(ctrl[j], feet[j], target, degree=degree, free_ends=ends, closed=closed)
            answer = spline_values(fixed, feet[j], degree=degree)[0]
            # checked as the answer is (geometry.validity.new_crossings), not only as the fit saw it
            if not new_crossings([inputs[i]], [answer])[0]:
                break
        else:
            tangled.append(i)
        out[i] = dataclasses.replace(row, ctrl=fixed, repair=fixed - ctrl[j])  # float64: the fit's own digits
    return out, tangled


def _closed_ctrl(points: np.ndarray, row: ReadCurve) -> np.ndarray:
    """The row's control points (float64) as its answer draws them: joined for a closed input."""
    c = np.asarray(row.ctrl, np.float64)
    return joined_ends(c) if is_closed(points) else c


def mixed_repairs(rows: Sequence[ReadCurve], weights: np.ndarray, *, what: str = "repair") -> np.ndarray | None:
    """Each weight row's share of the rows' repairs (or of another move of their control points, `what`: "pin"),
    (len(weights), n_ctrl, 2); None where no row has one."""
    repairs = [getattr(r, what) for r in rows]
    if all(r is None for r in repairs):
        return None
    like = next(r for r in repairs if r is not None)
    stacked = np.stack([np.zeros_like(like) if r is None else r for r in repairs])  # (inputs, n_ctrl, 2)
    return np.stack([(w[:, None, None] * stacked).sum(axis=0) for w in np.asarray(weights, np.float64)])


def untangle_mixes(
    ctrl: np.ndarray, params: Sequence[np.ndarray], targets: _Indexed, *, degree: int
) -> tuple[np.ndarray, np.ndarray]:
    """In-betweens (rows, n_ctrl, 2) whose splines at their `params` (n_k,) cross themselves, untangled against
    `targets[k]` (n_k, 2), the blend of their ends at those points (asked for only for the rows that cross): the
    control points, and which rows were repaired.
    A row whose target crosses itself too is left as it is (its ends cannot be joined there by a valid blend)."""
    c = np.array(ctrl, np.float64)
    lengths = np.array([len(u) for u in params])
    owner = np.repeat(np.arange(len(c)), lengths)
    flat = spline_values(c, np.concatenate(params), owner, degree=degree)[0] if len(c) else np.zeros((0, 2))
    points = np.split(flat, np.cumsum(lengths)[:-1])
    bad = crosses(points)
    repaired = np.zeros(len(c), bool)
    if bad.any():
        rows = np.flatnonzero(bad)
        aims = {int(k): targets[int(k)] for k in rows}
        for k in (int(k) for k in rows[~crosses(list(aims.values()))]):
            c[k], _ = untangled(c[k], params[k], aims[k], degree=degree)
            repaired[k] = True
    return c, repaired
