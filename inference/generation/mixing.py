"""Curves mixed from prepared curves' latents (paper eqs. 9, 10): the decoding of each weight row, brought to the
caller's frame, carrying its ends' repairs and untangled where it crosses itself (inference.placing)."""

from __future__ import annotations

import numpy as np

from curve_vae.geometry import Frame, blend_frames
from curve_vae.geometry.adapt import is_closed, joined_ends, spline_params
from curve_vae.geometry.bspline import spline_values
from curve_vae.geometry.validity import crosses
from curve_vae.inference.model.graphs import ModelGraphs
from curve_vae.inference.placing import (
    check_finite,
    check_range,
    joined,
    mixed_repairs,
    pinned_mixes,
    to_caller,
    untangle_mixes,
)
from curve_vae.inference.prepared import Prepared
from curve_vae.inference.results import Interpolation, head_splines


def mix(
    g: ModelGraphs, prep: Prepared, weights: np.ndarray, *, n_points: int | None, spacing: str, length: int
) -> Interpolation:
    """Decode weight rows (rows, len(prep.inputs)) over the prepared curves' means (runtime.interpolate says what
    comes back); `length`: the points per curve when there are no rows."""
    w = np.asarray(weights, np.float64)
    mean = prep.mean.astype(np.float64)
    auto = bool(prep.rows) and prep.rows[0].frame is not None
    with np.errstate(all="ignore"):
        # Row by row, never a matrix product: BLAS sums in an order that depends on the number of rows, and
        # a curve must not change with the batch or page it is made in.
        z = (w[:, :, None] * mean[None, :, :]).sum(axis=1)  # (rows, latent_dim)
        check_range(z, "weights")
        out, ctrl, params = g.decode(z)
        check_finite(out, "weights", "the weighted latent decodes to non-finite coordinates: weights too extreme")
        given = [f for f in prep.frames if f is not None]
        frames: list[Frame | None] = (
            [blend_frames(given, w[k : k + 1])[0] for k in range(len(w))] if auto else [None] * len(w)
        )
        lengths = {len(c) for c in prep.inputs}
        common = lengths.pop() if len(lengths) == 1 else None
        placed = prep.placed or all(f is not None for f in prep.fractions)
        blend = n_points is None and common is not None and placed
        closed = bool(prep.inputs) and all(is_closed(c) for c in prep.inputs)  # loops mix into loops
        positions = _positions(prep, w) if blend else None
        repaired = np.zeros(len(w), bool)
        if ctrl is not None:
            ctrl = _ends_kept(g, prep, w, ctrl, frames, closed)
            ctrl, repaired = _valid_ctrl(g, prep, w, ctrl, params, positions, n_points, spacing)
        results, splines = [], []
        for k, o in enumerate(out):
            c, u = None if ctrl is None else ctrl[k], None if params is None else params[k]
            if closed:
                o, c = joined(o, c)
            if positions is not None:  # placed: blend the spline parameters of the input points (not the head's)
                head = u if not prep.placed else None
                curve, spline = to_caller(g, o, frames[k], n_points=None, fractions=positions[k], ctrl=c, params=head)
            else:
                curve, spline = to_caller(g, o, frames[k], n_points=n_points, spacing=spacing, ctrl=c, params=u)
            results.append(curve)
            splines.append(spline)
        result = np.stack(results) if results else np.zeros((0, length, 2))
    check_finite(result, "weights", "the interpolant does not fit in float64")
    return Interpolation(
        result,
        frames,
        head_splines(splines, g.has_splines),
        weights=w,
        valid=~crosses(list(result)),
        repaired=repaired,
    )


def _ends_kept(
    g: ModelGraphs, prep: Prepared, w: np.ndarray, ctrl: np.ndarray, frames: list[Frame | None], closed: bool
) -> np.ndarray:
    """The rows' control points (float64) carrying their ends' moves in proportion, onto their inputs' ends and out of
    crossings (a row [1, 0] is its first end's answer), joined where every input is closed, and moved onto the blend
    of the inputs' matching ends (inference.placing)."""
    ctrl = ctrl.astype(np.float64)
    for what in ("pin", "repair"):
        shares = mixed_repairs(prep.rows, w, what=what)
        if shares is not None:
            ctrl += shares
    if closed:
        ctrl = joined_ends(ctrl)
    if not prep.ends_kept:
        return ctrl
    return pinned_mixes(ctrl, prep.inputs, prep.frames, w, frames, model_size=g.model_size, degree=g.spline_degree)


def _valid_ctrl(
    g: ModelGraphs,
    prep: Prepared,
    w: np.ndarray,
    ctrl: np.ndarray,
    params: np.ndarray | None,
    positions: np.ndarray | None,
    n_points: int | None,
    spacing: str,
) -> tuple[np.ndarray, np.ndarray]:
    """The rows' control points with those that cross untangled against the blend of their ends
    (inference.placing); and which rows carry a repair, their ends' or their own."""
    shares = mixed_repairs(prep.rows, w)
    carried = np.zeros(len(w), bool) if shares is None else np.abs(shares).reshape(len(w), -1).max(axis=1) > 0
    if not len(w):
        return ctrl, carried
    heads = [None if params is None else params[k] for k in range(len(w))]
    at = [_params_of(g, ctrl[k], heads[k], positions, k, prep.placed, n_points, spacing) for k in range(len(w))]
    targets = _Targets(g, prep, w, at, positions is not None and prep.placed)
    ctrl, repaired = untangle_mixes(ctrl, at, targets, degree=g.spline_degree)
    return ctrl, repaired | carried


def _params_of(
    g: ModelGraphs,
    ctrl: np.ndarray,
    head: np.ndarray | None,
    positions: np.ndarray | None,
    k: int,
    placed: bool,
    n_points: int | None,
    spacing: str,
) -> np.ndarray:
    """The parameters at which row k's spline is returned (as `to_caller` evaluates it)."""
    if positions is not None:
        u = spline_params(
            ctrl,
            degree=g.spline_degree,
            model_points=g.n_points,
            fractions=positions[k],
            model_params=None if placed else head,
        )
    else:
        u = spline_params(
            ctrl, degree=g.spline_degree, model_points=g.n_points, n_points=n_points, spacing=spacing, model_params=head
        )
    return np.linspace(0.0, 1.0, n_points or g.n_points) if u is None else u


class _Targets:
    """What in-between k should pass close to at its parameters `at[k]`, made only for the rows that need one: where
    the inputs were placed on their splines and share a length, the blend of their answers point for point; else the
    blend of the ends at the same parameter, along each end's answer where it has one."""

    def __init__(self, g: ModelGraphs, prep: Prepared, w: np.ndarray, at: list[np.ndarray], placed: bool) -> None:
        self.g, self.prep, self.w, self.at, self.placed = g, prep, w, at, placed
        self._ends: tuple[np.ndarray, list[np.ndarray], list[np.ndarray]] | None = None

    def ends(self) -> tuple[np.ndarray, list[np.ndarray], list[np.ndarray]]:
        """The ends' control points, their points' parameters and their answers (made once)."""
        if self._ends is None:
            ctrl = _end_ctrl(self.g, self.prep)
            feet = [np.asarray(r.feet, np.float64) for r in self.prep.rows] if self.prep.placed else []
            answers = [spline_values(e, f, degree=self.g.spline_degree)[0] for e, f in zip(ctrl, feet)]
            self._ends = ctrl, feet, answers
        return self._ends

    def __getitem__(self, k: int) -> np.ndarray:
        ctrl, feet, answers = self.ends()
        row, u = self.w[k], self.at[k]
        if self.placed:
            return np.tensordot(row, np.stack(answers), axes=1)
        if answers:  # along each end's answer (a valid polyline), where its points sit on its spline
            each = np.stack([np.stack([np.interp(u, f, a[:, d]) for d in (0, 1)], 1) for f, a in zip(feet, answers)])
        else:
            owner = np.repeat(np.arange(len(ctrl)), len(u))
            each = spline_values(ctrl, np.tile(u, len(ctrl)), owner, degree=self.g.spline_degree)[0]
            each = each.reshape(len(ctrl), -1, 2)
        return np.tensordot(row, each, axes=1)


def _end_ctrl(g: ModelGraphs, prep: Prepared) -> np.ndarray:
    """Each input's control points (inputs, n_ctrl, 2) as its answer draws them: repaired, joined where closed;
    decoded here where the reading did not decode them."""
    if all(r.ctrl is not None for r in prep.rows):
        ctrl = np.stack([np.asarray(r.ctrl, np.float64) for r in prep.rows])
    else:
        decoded = g.decode(prep.mean.astype(np.float64))[1]
        assert decoded is not None  # a B-spline head: mix only untangles where there are control points
        ctrl = decoded.astype(np.float64)
    # each joined where its own input is closed: its answer (a mix joins its ends only when every input is closed)
    return np.stack([joined_ends(c) if is_closed(p) else c for c, p in zip(ctrl, prep.inputs)])


def _positions(prep: Prepared, w: np.ndarray) -> np.ndarray:
    """Each row's blend of the input points' positions along their curves (rows, n): their spline parameters where
    placed on the splines, else where they sit along the model's points."""
    at = prep.feet if prep.placed else prep.fractions
    positions = w @ np.stack([a for a in at if a is not None])  # every input's (`placed`)
    return np.maximum.accumulate(np.clip(positions, 0.0, 1.0), axis=1)  # extrapolating rows stay ordered
