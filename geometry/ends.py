"""Answers that start and end where they should: a clamped B-spline's end points moved onto given points.

A clamped B-spline starts at its first control point and ends at its last, so an end is moved by moving that control
point. The move fades over the control points near the end (by their Greville abscissae, the parameter each one pulls
hardest at) as a smoothstep: 1 at the end, 0 beyond its reach, flat at both, so the curve near an end is shifted
rather than bent. The reach grows with the move: REACH_PER_MOVE times the move's share of the curve's length (its
control polygon's), so a small correction (a reconstruction's end, a few thousandths of its size off) moves the end
control point alone and a large one (an in-between's, a few hundredths) fades over a longer stretch. A closed curve's
two ends are moved onto one point and stay one.

    pinned_ends(ctrl, starts, ends, per_move=8.0)   # (B, n_ctrl, 2) control points, (B, 2) start and end points
"""

from __future__ import annotations

import numpy as np


def greville(n_ctrl: int, degree: int) -> np.ndarray:
    """(n_ctrl,) the Greville abscissae of a clamped uniform B-spline: the mean of each control point's `degree`
    inner knots, from 0 to 1."""
    from curve_vae.geometry.bspline import clamped_uniform_knots

    knots = clamped_uniform_knots(n_ctrl, degree)
    return np.array([knots[j + 1 : j + degree + 1].mean() for j in range(n_ctrl)])


def fading(abscissae: np.ndarray, reach: np.ndarray) -> np.ndarray:
    """(B, n) a smoothstep from 1 at abscissa 0 to 0 at each row's `reach` (B,), and 0 beyond."""
    s = np.clip(abscissae[None, :] / np.maximum(reach, 1e-12)[:, None], 0.0, 1.0)
    return 1.0 - s * s * (3.0 - 2.0 * s)


def pinned_ends(
    ctrl: np.ndarray, starts: np.ndarray, ends: np.ndarray, *, per_move: float, degree: int = 3
) -> np.ndarray:
    """Control points (B, n_ctrl, 2) moved so that each spline starts at `starts[b]` and ends at `ends[b]` (B, 2),
    each move fading over a reach (a share of the parameter) of `per_move` times its share of the curve's length
    (float64)."""
    c = np.array(ctrl, np.float64)
    if not len(c):
        return c
    g = greville(c.shape[1], degree)
    length = np.maximum(np.linalg.norm(np.diff(c, axis=1), axis=2).sum(axis=1), 1e-300)
    d0 = np.asarray(starts, np.float64) - c[:, 0]
    d1 = np.asarray(ends, np.float64) - c[:, -1]
    first = fading(g, per_move * np.linalg.norm(d0, axis=1) / length)
    last = fading(1.0 - g, per_move * np.linalg.norm(d1, axis=1) / length)
    c += first[:, :, None] * d0[:, None, :] + last[:, :, None] * d1[:, None, :]
    c[:, 0], c[:, -1] = starts, ends  # exactly, whatever the shares' rounding
    return c
