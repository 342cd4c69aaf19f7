"""Fitting a reconstruction to its curve: the encoder's latent refined so that the decoded B-spline passes closer to
the caller's points.

The encoder maps a curve to a latent in one pass; the decoder's best latent for that curve is usually nearby but not
there. `Fitter.refine_latents` takes `steps` Levenberg–Marquardt steps on each latent, minimising the squared distance
from the curve's own points to the decoded spline, each point measured to its closest point on the spline (foot points,
`geometry.closest_params`, searched near the previous ones). Because the points are matched to their closest points and
not to fixed parameters, the distance minimised does not depend on how the caller spaced the points along the curve
(the encoder's latent it starts from does: see docs/RESULTS.md). The Jacobian of
the control points with respect to the latent comes from forward differences (latent_dim decoder runs per curve)
every JACOBIAN_EVERY steps and from Broyden's rank-one update in between (one run per curve per step); a step that
does not lower the distance is undone and the damping raised. Torch-free: the decoder is the ONNX graph.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np
from scipy.interpolate import BSpline
from scipy.optimize import isotonic_regression

from curve_vae.geometry import arc_fractions, closest_params, params_at_arc_fractions
from curve_vae.inference.prepared import ReadCurve

if TYPE_CHECKING:
    from curve_vae.inference.model.graphs import ModelGraphs

#: A decoding: curves (B, n_points, 2), control points (B, n_ctrl, 2), learned parameters (B, n_points) or None.
Decoding = tuple[np.ndarray, np.ndarray, np.ndarray | None]

#: Forward-difference step in latent units (the latent prior is a unit Gaussian; the decoder runs in float32).
FD_STEP = 1e-2
#: How far along the spline (in its parameter) a point's match may move in one step.
FOOT_WINDOW = 0.05
#: Steps between forward-difference Jacobians; the steps in between update it by Broyden's rule from the step just
#: tried (one decoder run per curve). Every 5th step: 10 steps cost about a third of a fresh Jacobian at every step,
#: for nearly the same fit (scripts/refine_tradeoff.py --jacobian-every).
JACOBIAN_EVERY = 5


class Fitter:
    """The latent refinement of `refine`, through a model's decoder graph (its B-spline head)."""

    def __init__(self, graphs: ModelGraphs) -> None:
        self.graphs = graphs
        self.knots = graphs.knots
        self.spline_degree = graphs.spline_degree

    def refine(self, inputs: Sequence[np.ndarray], rows: Sequence[ReadCurve], steps: int) -> list[ReadCurve]:
        """The rows with their latents fitted to the caller's own points by `steps` steps: each mean becomes the
        fitted latent (the log-variance stays the encoder's), decoded, and each caller point is matched to its
        closest point on the fitted spline (`ReadCurve.feet`), starting from where the reading put it."""
        g = self.graphs
        targets, around = [], []
        for pts, r in zip(inputs, rows):
            targets.append(r.frame.to_model(pts, g.model_size) if r.frame is not None else pts)
            if r.feet is not None:
                around.append(r.feet)
            else:
                a = np.linspace(0.0, 1.0, len(pts)) if r.fraction is None else r.fraction
                if r.params is not None:  # the head's own parameters at those positions
                    a = np.interp(a, np.linspace(0.0, 1.0, g.n_points), r.params)
                around.append(a)
        decoded = all(r.decoded_yet for r in rows) and bool(rows)
        known = (
            (
                np.stack([r.decoded for r in rows if r.decoded is not None]),  # every row's: all decoded
                np.stack([r.ctrl for r in rows if r.ctrl is not None]),  # a B-spline head's: every row has them
                None if rows[0].params is None else np.stack([r.params for r in rows if r.params is not None]),
            )  # fmt: skip
            if decoded
            else None
        )
        mean = np.stack([r.mean for r in rows]) if rows else np.zeros((0, g.latent_dim))
        with np.errstate(all="ignore"):
            z, (out, ctrl, params), feet = self.refine_latents(mean, targets, around, steps, decoded=known)
        return [
            dataclasses.replace(
                r,
                mean=z[i].astype(np.float32),
                decoded=out[i].astype(np.float32),
                ctrl=ctrl[i].astype(np.float32),
                params=None if params is None else params[i],
                feet=feet[i],
            )
            for i, r in enumerate(rows)
        ]

    def refine_latents(
        self,
        latents: np.ndarray,
        targets: Sequence[np.ndarray],
        around: Sequence[np.ndarray],
        steps: int,
        *,
        decoded: Decoding | None = None,
    ) -> tuple[np.ndarray, Decoding, list[np.ndarray]]:
        """`steps` damped Gauss–Newton steps on each latent (B, latent_dim) towards its curve `targets[i]` (n_i, 2),
        model plane, whose points start matched to spline parameters `around[i]` (n_i,).

        Returns the refined latents (float64), their decoding (curves, control points, learned parameters or None)
        and each target point's parameter on its refined spline. Never further from the targets than the latents
        given at `around`: a curve whose step raises its distance keeps the previous latent. A fresh Jacobian every
        JACOBIAN_EVERY steps (read at each call, so a measurement can set it). `decoded`: the latents' decoding
        when the caller has it already.
        """
        assert self.knots is not None, "refinement needs a B-spline head"
        z = np.array(latents, np.float64)
        count, dim = z.shape
        fit = _float64(decoded if decoded is not None else self.graphs.decode(z))
        # the start: two guesses of where the target's points sit (its positions as given, and the same fractions of
        # the spline's length as of the target's); the closest points searched near the closer guess, or a guess
        # itself where closer still (pooling points into order can cost more than it gains), so that the fit is
        # never further than the plain reconstruction
        feet, cost = self._start(fit[1], targets, around)
        damping = np.full(count, 1e-2)
        jac = np.zeros(0)
        for step in range(steps if count else 0):
            if step % JACOBIAN_EVERY == 0:
                shifted = (z[:, None, :] + FD_STEP * np.eye(dim)[None]).reshape(-1, dim)
                moved = self.graphs.decode(shifted)[1]
                assert moved is not None, "refinement needs a B-spline head"
                jac = (moved.astype(np.float64).reshape(count, dim, -1, 2) - fit[1][:, None]) / FD_STEP
            trial = self._step(z, fit[1], jac, targets, feet, damping)
            with np.errstate(all="ignore"):
                tried = _float64(self.graphs.decode(trial))
            tried_feet, tried_cost = self._placed(tried[1], targets, feet)
            # Broyden's update of each curve's Jacobian by the step just tried (accepted or not)
            dz, dc = trial - z, tried[1] - fit[1]
            norm = (dz**2).sum(1)
            ok = (norm > 0) & np.isfinite(dc).reshape(count, -1).all(1)
            miss = dc - np.einsum("bl,blkd->bkd", dz, jac)
            jac[ok] += dz[ok, :, None, None] * miss[ok, None] / norm[ok, None, None, None]
            better = tried_cost < cost
            z[better], cost[better] = trial[better], tried_cost[better]
            fit = _kept(better, fit, tried)
            feet = [tf if b else f for b, tf, f in zip(better, tried_feet, feet)]
            damping = np.where(better, damping / 3, damping * 4)
        return z, fit, feet

    def _start(
        self, ctrl: np.ndarray, targets: Sequence[np.ndarray], around: Sequence[np.ndarray]
    ) -> tuple[list[np.ndarray], np.ndarray]:
        """Where each target's points start on its spline, and the squared distance there: the closest points
        searched near the closer of two guesses (the positions given, and the same fractions of the spline's
        length as of the target's), or a guess itself where closer still."""
        feet, cost = [], np.empty(len(ctrl))
        for i, (c, t, a) in enumerate(zip(ctrl, targets, around)):
            guesses = [(self._cost(c, t, g), g) for g in (np.asarray(a, np.float64), *_along(c, t))]
            closest = self._feet(c, t, min(guesses, key=lambda guess: guess[0])[1])
            cost[i], u = min([(self._cost(c, t, closest), closest), *guesses], key=lambda start: start[0])
            feet.append(u)
        return feet, cost

    def _step(
        self,
        z: np.ndarray,
        ctrl: np.ndarray,
        jac: np.ndarray,
        targets: Sequence[np.ndarray],
        feet: Sequence[np.ndarray],
        damping: np.ndarray,
    ) -> np.ndarray:
        """Each latent's damped Gauss–Newton step (Levenberg–Marquardt) on its points' distances at `feet`."""
        dim = z.shape[1]
        trial = z.copy()
        for i in range(len(z)):
            basis = self._basis(feet[i])
            residual = (targets[i] - basis @ ctrl[i]).reshape(-1)
            j = np.einsum("nk,lkd->ndl", basis, jac[i]).reshape(-1, dim)
            a = j.T @ j
            a += damping[i] * np.diag(np.diag(a)) + 1e-9 * (np.trace(a) / dim + 1e-12) * np.eye(dim)
            try:
                trial[i] = z[i] + np.linalg.solve(a, j.T @ residual)
            except np.linalg.LinAlgError:  # a Jacobian of non-finite numbers: this curve stays where it is
                trial[i] = z[i]
        return trial

    def _placed(
        self, ctrl: np.ndarray, targets: Sequence[np.ndarray], feet: Sequence[np.ndarray]
    ) -> tuple[list[np.ndarray], np.ndarray]:
        """The tried splines' feet (searched near the current ones) and squared distances; inf where a spline is
        not finite (its feet stay)."""
        tried_feet, tried_cost = [], np.full(len(ctrl), np.inf)
        for i, c in enumerate(ctrl):
            if np.isfinite(c).all():
                u = self._feet(c, targets[i], feet[i])
                tried_cost[i] = self._cost(c, targets[i], u)
                tried_feet.append(u)
            else:
                tried_feet.append(feet[i])
        return tried_feet, tried_cost

    def _feet(self, ctrl: np.ndarray, target: np.ndarray, around: np.ndarray) -> np.ndarray:
        """Each target point's closest point on the spline near `around`, kept in the points' order: the curve's
        ends stay its ends (the first and last points at parameters 0 and 1, as without refinement), and where
        closest points come out of order (points around a corner sharper than the spline's, all closest to its
        rounded tip) they are pooled to the least-squares non-decreasing sequence (isotonic regression), so the
        returned points never step back along the curve."""
        u = closest_params(ctrl, target, around, window=FOOT_WINDOW, degree=self.spline_degree)
        u[0], u[-1] = 0.0, 1.0
        return np.asarray(isotonic_regression(u).x, np.float64)

    def _basis(self, u: np.ndarray) -> np.ndarray:
        """(n, n_ctrl) B-spline basis of the head at parameters u."""
        return BSpline.design_matrix(np.clip(u, 0.0, 1.0), self.knots, self.spline_degree).toarray()

    def _cost(self, ctrl: np.ndarray, target: np.ndarray, u: np.ndarray) -> float:
        """Sum of squared distances from the target's points to the spline at u (scipy's evaluation: no matrix)."""
        spline = BSpline(self.knots, np.asarray(ctrl, np.float64), self.spline_degree)
        return float(((target - spline(np.clip(u, 0.0, 1.0))) ** 2).sum())


def _along(ctrl: np.ndarray, target: np.ndarray) -> list[np.ndarray]:
    """A second first guess of where the target's points sit on the spline: at the same fractions of its length as
    along the target (a guess whatever the target's spacing, for a spline of the target's shape); none for a target
    whose points all coincide."""
    try:
        return [params_at_arc_fractions(ctrl, arc_fractions(target), dense=1024)]
    except ValueError:
        return []


def _float64(decoded: tuple[np.ndarray, np.ndarray | None, np.ndarray | None]) -> Decoding:
    """A decoding (curves, control points, parameters or None) in float64, for the differences of the fit; the
    control points are there (refinement needs a B-spline head)."""
    out, ctrl, params = decoded
    assert ctrl is not None, "refinement needs a B-spline head"
    return out.astype(np.float64), ctrl.astype(np.float64), None if params is None else params.astype(np.float64)


def _kept(better: np.ndarray, old: Decoding, new: Decoding) -> Decoding:
    """Each row of the decoding `new` where `better` (B,) says so, of `old` elsewhere (one graph decoded both, so
    both have learned parameters or neither has)."""

    def pick(o: np.ndarray, n: np.ndarray) -> np.ndarray:
        return np.where(_rows(better, o), n, o)

    params = None if old[2] is None or new[2] is None else pick(old[2], new[2])
    return pick(old[0], new[0]), pick(old[1], new[1]), params


def _rows(mask: np.ndarray, like: np.ndarray) -> np.ndarray:
    """A row mask (B,) shaped to broadcast against `like` (B, …)."""
    return mask.reshape((-1,) + (1,) * (like.ndim - 1))
