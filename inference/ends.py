"""Answers that keep their inputs' ends (geometry.ends): a reconstruction starts and ends where its input does, an
in-between at the weighted blend of its inputs' matching ends, so an end the inputs share is shared by every curve
between them; a closed input's answer closes at its input's closing point.

Ends match as the set is read, in one pose: each input's end at the model's parameter 0 (its first point, or its last
where its pose reverses it) with the others' there. Blends are taken in the caller's plane, where the inputs are.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence

import numpy as np

from curve_vae.geometry import Frame
from curve_vae.geometry.adapt import is_closed
from curve_vae.geometry.batch import FrameRows
from curve_vae.geometry.ends import pinned_ends
from curve_vae.inference.prepared import ReadCurve

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
