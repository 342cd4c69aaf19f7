"""Valid shapes: whether a returned curve crosses itself where its input does not, and the local repair of a
B-spline answer that does.

A reconstruction is close on average (~0.1% of the curve's diagonal) but a thin part of a shape — an airfoil's
trailing edge, where the two surfaces meet at a few thousandths of the chord — can be thinner than that error, and
the decoded sides cross. Such an answer is not a shape a user can mesh or cut. `untangled` refits the control points
of the spline around each crossing, by least squares, to the points the answer should pass through at their own
parameters (for a reconstruction the input's points; for an in-between the blend of its ends' answers), the rest of
the spline held: a B-spline's control point moves only the four spans it supports, so the answer elsewhere is the
decoder's to the bit. On the family suite's 200 UIUC airfoils it uncrossed all 24 default answers that crossed, each
closer to its input than before (scripts/valid_shapes.py, docs/RESULTS.md).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import shapely

from curve_vae.geometry.bspline import basis_and_slope

#: Rounds of `untangled`: each frees the control points around the crossings still left, one span wider each round.
UNTANGLE_ROUNDS = 4
#: Weight of each freed control point's pull towards where it was, against the basis' values (at most 1) at the points.
STEADY = 1e-3


def crosses(curves: Sequence[np.ndarray]) -> np.ndarray:
    """Whether each polyline (n_i, 2) crosses or touches itself, (B,) bool; a closed one (its last point its first)
    may meet itself there. All at once: GEOS's simplicity test per curve, no Python loop over points."""
    if not len(curves):
        return np.zeros(0, bool)
    pts = np.concatenate([np.asarray(c, np.float64).reshape(-1, 2) for c in curves])
    owner = np.repeat(np.arange(len(curves)), [len(c) for c in curves])
    with np.errstate(all="ignore"):
        return ~shapely.is_simple(shapely.linestrings(pts, indices=owner))


def new_crossings(inputs: Sequence[np.ndarray], outputs: Sequence[np.ndarray]) -> np.ndarray:
    """(B,) bool: the outputs that cross themselves where their inputs do not (an input that crosses itself may
    come back crossing: that is its shape)."""
    bad = crosses(outputs)
    if bad.any():
        idx = np.flatnonzero(bad)
        bad[idx] = ~crosses([inputs[int(i)] for i in idx])
    return bad


def crossing_segments(points: np.ndarray) -> np.ndarray:
    """(m, 2) index pairs (j, k), j < k, of the segments (point i to i + 1) of a polyline that meet though they are
    not neighbours; a closed polyline's first and last segments meet at its join and are not counted."""
    p = np.asarray(points, np.float64)
    segs = shapely.linestrings(np.stack([p[:-1], p[1:]], axis=1))
    j, k = shapely.STRtree(segs).query(segs, predicate="intersects")
    keep = k > j + 1
    if len(p) > 2 and np.array_equal(p[0], p[-1]):
        keep &= ~((j == 0) & (k == len(segs) - 1))
    return np.stack([j[keep], k[keep]], axis=1)


def untangled(
    ctrl: np.ndarray,
    params: np.ndarray,
    target: np.ndarray,
    *,
    degree: int = 3,
    free_ends: bool = False,
    closed: bool = False,
) -> tuple[np.ndarray, bool]:
    """A clamped uniform B-spline's control points (n_ctrl, 2) with those around its crossings refitted so that the
    spline at `params` (n,) passes close to `target` (n, 2), and whether it is now free of crossings.

    The spline at `params` is the answer (the caller's points placed on it). Each round frees the control points
    whose spans hold a crossing's segments, one span beyond on either side (a span wider each round), and solves
    for them by least squares against `target` with every other control point held. The two end control points (the
    answer's ends, kept where its input's are: inference.placing) are held too, unless `free_ends` (the last resort:
    a closed spline's two ends then move as one point). Returned unchanged (and True) when it does not cross."""
    c = np.array(ctrl, np.float64)
    u = np.clip(np.asarray(params, np.float64), 0.0, 1.0)
    n_ctrl = len(c)
    basis = basis_and_slope(u, n_ctrl, degree)[0]  # (n, n_ctrl)
    spans = n_ctrl - degree
    lo, hi = (0, n_ctrl - 1) if free_ends else (1, n_ctrl - 2)
    free: set[int] = set()
    for margin in range(1, UNTANGLE_ROUNDS + 1):
        pairs = crossing_segments(basis @ c)
        if not len(pairs):
            return c, True
        at = u[np.concatenate([pairs.ravel(), pairs.ravel() + 1])]
        for s in np.unique(np.minimum((at * spans).astype(np.int64), spans - 1)):
            free.update(range(max(int(s) - margin, lo), min(int(s) + degree + margin, hi) + 1))
        if not free:
            break
        groups = _unknowns(sorted(free), n_ctrl, closed)
        held = np.ones(n_ctrl, bool)
        held[[i for g in groups for i in g]] = False
        rhs = target - basis[:, held] @ c[held]
        # a little pull to where each free point was: a control point whose spans hold few of the points is still
        # decided (and the answer the same, to rounding, whatever the curve's scale or pose)
        columns = np.hstack([basis[:, g].sum(axis=1, keepdims=True) for g in groups])
        columns = np.vstack([columns, STEADY * np.eye(len(groups))])
        now = np.stack([c[g].mean(axis=0) for g in groups])
        solved = np.linalg.lstsq(columns, np.vstack([rhs, STEADY * now]), rcond=None)[0]
        if not np.isfinite(solved).all():
            break
        for g, value in zip(groups, solved):
            c[g] = value
    return c, not len(crossing_segments(basis @ c))


def _unknowns(free: list[int], n_ctrl: int, closed: bool) -> list[list[int]]:
    """Which control points each unknown sets: each free one its own, but a closed spline's two ends one (its loop
    stays joined)."""
    ends = [0, n_ctrl - 1]
    if closed and (0 in free or n_ctrl - 1 in free):
        return [ends] + [[f] for f in free if f not in ends]
    return [[f] for f in free]
