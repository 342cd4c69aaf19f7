"""Answers that are valid shapes: a reconstruction or an in-between that crosses itself where its input does not is
untangled (geometry.validity.untangled) before it is returned, and says so.

A reconstruction placed on its spline (a B-spline head, closest placement or refine: the shipped model's) is the
spline at its points' parameters; where it crosses itself and its input does not, the control points around the
crossing are refitted to the input's own points. The change of control points is kept with the row
(`ReadCurve.repair`), so that curves mixed from it carry it in proportion: an in-between's control points get the
weighted sum of its ends' repairs, and a row [1, 0] is its first end's answer to the bit. An in-between that still
crosses is refitted the same way near its crossings, to the blend of its ends' answers at its points (what the
point-wise blend of two valid, similar shapes is: valid where they are alike).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from typing import Protocol

import numpy as np

from curve_vae.geometry.adapt import is_closed, joined_ends
from curve_vae.geometry.bspline import spline_values
from curve_vae.geometry.validity import crosses, new_crossings, untangled
from curve_vae.inference.prepared import ReadCurve


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
