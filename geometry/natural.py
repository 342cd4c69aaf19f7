"""A curve's natural parameters: where each of its points would sit on a cubic B-spline like the paper's.

The paper's curves are clamped uniform cubic B-splines with 10 control points, sampled evenly in their parameter;
the encoder reads curves best at that spacing. A curve drawn by arc length (a stroke, a coordinate file) has lost
it. `natural_params` recovers it by fitting such a spline and each point's parameter together
(Levenberg–Marquardt, the parameters eliminated by their Schur complement, so a step solves a 2·n_ctrl system).

The fit has many local minima: along gentle stretches the points can slide a long way for a small gain. Of the
paper's curves drawn by arc length, the spline at each point's own parameter is 0.007% of the diagonal from the
points, while the fit from their arc-length fractions stops at 0.06% after 40 steps, its reading 13% of the
diagonal from their own spacing (medians, scripts/natural_spacing.py). So the fit starts from several guesses at
once (batched): the arc-length fractions and fractions of lengths stretched where the curve turns (a B-spline's
parameter runs slowly where it turns sharply); it runs them all a few steps and carries on with the closest and
with the one from the arc-length fractions. The closest lands on a paper curve's own parameters for half of them.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np
from scipy.ndimage import gaussian_filter1d

from curve_vae.errors import InvalidInput
from curve_vae.geometry.bspline import clamped_uniform_knots
from curve_vae.geometry.frame import CLOSED, arc_fractions
from curve_vae.geometry.metrics import turning_angles
from curve_vae.geometry.natural_kernel import fit_start, lm_steps

#: Control points of the spline whose parameters `natural_params` finds: the paper's curves have 10.
NATURAL_CTRL = 10

#: Most points `natural_params` fits; the parameters of the points between them are interpolated by arc length, so
#: a curve of 4,096 points costs what one of 321 does.
NATURAL_FIT_POINTS = 321

#: Where the fit starts besides the arc-length fractions: a length whose element is ds·(1 + strength·κ ÷ mean κ),
#: κ the curvature smoothed over `width` × the number of points.
NATURAL_STARTS: tuple[tuple[float, float], ...] = tuple((s, w) for s in (0.5, 1.0, 2.0, 4.0) for w in (0.0125, 0.0375))

#: Steps every start runs before the fit keeps only the closest and the arc-length one.
NATURAL_SCOUT_STEPS = 15

#: natural_readings_of's `arc_reading`: which curves keep the arc-length start's fit as a second reading.
ARC_READINGS = ("always", "loops_and_corners")
#: A turn at one point (radians, ~69°) past which "loops_and_corners" keeps it: the superellipses' corners, some of
#: whose answers came back crossing themselves from the closest start's reading alone (docs/RESULTS.md, service 0.21.0).
ARC_CORNER = 1.2

#: A guess at polylines' parameters: (n, 2) polylines of one length -> each one's parameters (n,).
Guess = Callable[[list[np.ndarray]], list[np.ndarray]]


def natural_params(points: np.ndarray, *, n_ctrl: int = NATURAL_CTRL, steps: int = 40) -> np.ndarray:
    """Where each point of a polyline (n, 2) sits, as a parameter in [0, 1], on the clamped uniform cubic B-spline
    with `n_ctrl` control points that passes closest to the points (of the fits `natural_readings` makes).

    Reading a curve at even steps of these parameters gives it a spacing that a 10-point B-spline sampled evenly
    in its parameter — one of the paper's curves — could have, whatever spacing it was drawn at.
    """
    return natural_readings(points, n_ctrl=n_ctrl, steps=steps)[0]


def natural_readings(points: np.ndarray, *, n_ctrl: int = NATURAL_CTRL, steps: int = 40) -> list[np.ndarray]:
    """The parameters (n,) in [0, 1] of a polyline's points (n, 2) on a clamped uniform cubic B-spline with `n_ctrl`
    control points fitted to them together, `steps` Levenberg–Marquardt steps in all: first the closest fit of
    those from every start (module docstring), then, where it ends elsewhere, the fit from the points' arc-length
    fractions. The ends stay at 0 and 1, the parameters in order.

    The parameters follow the shape: they do not change when the curve is moved, turned, scaled or mirrored, and a
    reversed curve gets 1 − u reversed (the fit runs from the end the curve turns most towards, whichever way it is
    listed). Curves of fewer than 2·n_ctrl points keep their arc-length fractions; of a curve of more than
    NATURAL_FIT_POINTS points, that many are fitted and the rest interpolated by arc length between them.
    """
    return natural_readings_of([points], n_ctrl=n_ctrl, steps=steps)[0]


def natural_readings_of(
    curves: Sequence[np.ndarray],
    *,
    n_ctrl: int = NATURAL_CTRL,
    steps: int = 40,
    scout: int = NATURAL_SCOUT_STEPS,
    guess: Guess | None = None,
    arc_reading: str = "always",
) -> list[list[np.ndarray]]:
    """`natural_readings` of many polylines at once: the curves fitted with as many points are fitted together,
    every start of every curve one row of one Levenberg–Marquardt (a batch costs about what its longest curve's
    fit does, not the sum). `scout`: the steps every start runs before only the closest and the arc-length one go
    on (of `steps` in all). `guess`: where to start besides the arc-length fractions, instead of NATURAL_STARTS'
    stretched lengths — given the polylines as the fit sees them (each scaled, from the end it turns most towards,
    at most NATURAL_FIT_POINTS), their parameters (inference.spacer's guesses). `arc_reading`: "always", the fit
    from the arc-length fractions carries on beside the closest start's, a second reading where the two end apart;
    "loops_and_corners", only for a closed-looking curve (`frame.CLOSED`) or one that turns more than ARC_CORNER at
    a point, a smooth open curve getting the closest start's alone."""
    if arc_reading not in ARC_READINGS:
        raise ValueError(f"arc_reading must be one of {', '.join(ARC_READINGS)}, got {arc_reading!r}")
    out: list[list[np.ndarray]] = [[] for _ in curves]
    fits: dict[int, list[tuple[int, np.ndarray, bool, np.ndarray | None]]] = {}  # fitted length -> curves
    for i, points in enumerate(curves):
        pts = np.asarray(points, np.float64)
        extent = float(np.ptp(pts, axis=0).max()) if len(pts) else 0.0
        if not extent > 0:
            raise InvalidInput("all points coincide: a curve needs at least 2 distinct points")
        pts = (pts - pts[0]) / extent  # the shape alone, at a size where squares neither underflow nor overflow
        u = arc_fractions(pts)
        if len(pts) < 2 * n_ctrl:
            out[i] = [u]
            continue
        turn = turning_angles(pts)
        # fitted from the end where the curve turns most, whichever way it is listed: a curve and its reversal get
        # the same parameters to rounding (the fit's path from its start is not symmetric in the order)
        flip = bool(turn.sum() > 0 and (turn * u[1:-1]).sum() / turn.sum() > 0.5)
        pts = pts[::-1] if flip else pts
        some = None
        if len(pts) > NATURAL_FIT_POINTS:
            some = np.unique(np.round(np.linspace(0, len(pts) - 1, NATURAL_FIT_POINTS)).astype(int))
        fits.setdefault(len(pts) if some is None else len(some), []).append((i, pts, flip, some))
    for group in fits.values():
        fitted = _fit(
            [pts if some is None else pts[some] for _, pts, _, some in group], n_ctrl, steps, scout, guess, arc_reading
        )
        for (i, pts, flip, some), readings in zip(group, fitted):
            if some is not None:
                u = arc_fractions(pts)
                readings = [np.interp(u, u[some], r) for r in readings]
            out[i] = [(1.0 - r)[::-1] for r in readings] if flip else readings
    return out


def _rising(u: np.ndarray) -> np.ndarray:
    """A guess as the fit takes parameters: within [0, 1], never falling, its ends at 0 and 1."""
    u = np.maximum.accumulate(np.clip(np.asarray(u, np.float64), 0.0, 1.0))
    u[0], u[-1] = 0.0, 1.0
    return u


def _starts(pts: np.ndarray) -> np.ndarray:
    """(K, n) first guesses at a polyline's parameters: its arc-length fractions, then NATURAL_STARTS' lengths
    stretched where it turns (only the first for a straight polyline)."""
    ds = np.linalg.norm(np.diff(pts, axis=0), axis=1)
    turn = turning_angles(pts)
    local = (ds[:-1] + ds[1:]) / 2
    kappa = np.where(local > 0, turn / np.where(local > 0, local, 1.0), 0.0)  # at the inner points
    per_segment = np.concatenate([[kappa[0]], (kappa[:-1] + kappa[1:]) / 2, [kappa[-1]]])
    mean = (per_segment * ds).sum() / ds.sum()
    out = [np.concatenate([[0.0], np.cumsum(ds)]) / ds.sum()]
    if mean > 0:
        for strength, width in NATURAL_STARTS:
            k = gaussian_filter1d(per_segment, max(width * len(pts), 0.5), mode="nearest")
            s = np.concatenate([[0.0], np.cumsum(ds * (1 + strength * k / mean))])
            out.append(s / s[-1])
    return np.array(out)


def _fit(
    curves: list[np.ndarray],
    n_ctrl: int,
    steps: int,
    scout: int,
    guess: Guess | None = None,
    arc_reading: str = "always",
) -> list[list[np.ndarray]]:
    """`natural_readings_of`' fit of polylines of one length (n, 2) as listed, all at once: every start of every
    curve scouts, then each curve carries on with its closest start and the arc-length one (`arc_reading`)."""
    if guess is None:
        starts = [_starts(pts) for pts in curves]
    else:
        starts = [np.stack([arc_fractions(pts), _rising(g)]) for pts, g in zip(curves, guess(curves))]
    owner = np.concatenate([np.full(len(st), i) for i, st in enumerate(starts)])
    first = np.concatenate([[0], np.cumsum([len(st) for st in starts])[:-1]])  # each curve's arc-length row
    fit = _BatchFit(np.stack(curves)[owner], np.concatenate(starts), n_ctrl)
    fit.run(min(scout, steps))
    rows: list[int] = []
    for i in range(len(curves)):
        best = int(first[i] + fit.cost[owner == i].argmin())
        arc = best != first[i] and (arc_reading == "always" or _keeps_arc(curves[i]))
        rows += [best, int(first[i])] if arc else [best]
    fit.keep(rows)
    fit.run(steps - min(scout, steps))
    owner = owner[rows]
    out = []
    for i in range(len(curves)):
        mine = np.flatnonzero(owner == i)
        order = mine[np.argsort(fit.cost[mine], kind="stable")]
        if len(order) == 2 and np.abs(fit.u[order[0]] - fit.u[order[1]]).max() < 1e-6:  # both ended at one fit
            order = order[:1]
        out.append([fit.u[k].copy() for k in order])
    return out


def _keeps_arc(pts: np.ndarray) -> bool:
    """arc_reading "loops_and_corners": whether a polyline looks closed (its chord shorter than frame.CLOSED of its
    extent, twice its furthest point from its centroid: an airfoil, a loop) or turns more than ARC_CORNER at a point."""
    reach = 2 * np.linalg.norm(pts - pts.mean(axis=0), axis=1).max()
    return bool(np.hypot(*(pts[-1] - pts[0])) < CLOSED * reach or np.abs(turning_angles(pts)).max() > ARC_CORNER)


class _BatchFit:
    """K Levenberg–Marquardt fits at once, one per row of polylines (K, n, 2) and starting parameters (K, n): each
    a clamped uniform cubic B-spline (n_ctrl control points) and its points' parameters. The steps run compiled,
    without the GIL (geometry.natural_kernel); each step, per row:

    the parameters' block of the normal equations is diagonal (one tangent per point, |t|²(1 + λ)), so it is
    eliminated and the control points' 2·n_ctrl system is its Schur complement, Bᵀ·diag(w)·B block by block with the
    damping λ·ΣB² on its diagonal; the parameters follow from the control points' step, kept within [0, 1] and never
    falling, the ends at 0 and 1; a step is kept only where it brings the spline closer (λ ÷ 3), else λ × 4, and a
    row whose λ passes 1e8 has stopped."""

    def __init__(self, pts: np.ndarray, u: np.ndarray, n_ctrl: int) -> None:
        self.knots = clamped_uniform_knots(n_ctrl)
        self.pts = np.ascontiguousarray(pts, np.float64)
        self.u = np.array(u, np.float64)
        self.ctrl = np.zeros((len(u), n_ctrl, 2))
        self.cost = np.zeros(len(u))
        fit_start(self.knots, self.pts, self.u, self.ctrl, self.cost)  # least squares at the starting parameters
        self.damping = np.full(len(u), 1e-3)

    def keep(self, rows: list[int]) -> None:
        for name in ("pts", "u", "ctrl", "cost", "damping"):
            setattr(self, name, np.ascontiguousarray(getattr(self, name)[rows]))

    def run(self, steps: int) -> None:
        try:
            lm_steps(self.knots, self.pts, self.u, self.ctrl, self.cost, self.damping, steps)
        except np.linalg.LinAlgError:  # a singular step: every row keeps its last accepted one
            return
