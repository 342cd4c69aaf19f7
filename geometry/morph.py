"""How well a sweep of in-betweens morphs from one curve to another (paper §4, Fig. 10): it should turn and move as
its ends do, not swing round on the way.

Two measures of a sweep (steps, n, 2), its first and last curves its ends:

- `turn_excess`: how far (degrees) an in-between's chord (first point -> last) turns beyond the arc of directions
  between its ends' chords (the shorter way round); 0 for a sweep that turns monotonically from end to end.
- `end_drift`: how far an in-between's first and last points stray from the segments joining the ends' first points
  and the ends' last points, ÷ the diagonal of the ends' joint bounding box; 0 for point-wise blending.
"""

from __future__ import annotations

import numpy as np

from curve_vae.geometry.metrics import diagonal


def chord_directions(curves: np.ndarray) -> np.ndarray:
    """(steps,) the direction (radians) of each curve's chord, first point -> last."""
    c = np.asarray(curves, np.float64)
    d = c[:, -1] - c[:, 0]
    return np.arctan2(d[:, 1], d[:, 0])


def turn_excess(sweep: np.ndarray) -> float:
    """The largest angle (degrees) by which an in-between's chord lies outside the arc between the ends' chords."""
    a = chord_directions(sweep)
    start, span = a[0], _wrapped(a[-1] - a[0])  # the arc from the first end's chord to the last's, signed
    rel = _wrapped(a[1:-1] - start)  # each in-between's chord from the first end's
    if span < 0:  # measure along the arc's own direction
        rel, span = -rel, -span
    # outside [0, span]: how far past the nearer end of the arc, going round either way
    below = np.where(rel < 0, -rel, 0.0)
    above = np.where(rel > span, rel - span, 0.0)
    excess = np.minimum(np.maximum(below, above), 2 * np.pi - span - np.maximum(below, above))
    return float(np.degrees(excess.max())) if len(excess) else 0.0


def end_drift(sweep: np.ndarray) -> float:
    """The largest distance of an in-between's end point from the segment between the ends' same end points, ÷
    the diagonal of the ends' joint bounding box."""
    c = np.asarray(sweep, np.float64)
    ends = np.concatenate([c[0], c[-1]])
    size = float(diagonal(ends))
    worst = 0.0
    for k in (0, -1):
        a, b = c[0, k], c[-1, k]
        p = c[1:-1, k]
        ab = b - a
        t = np.clip(((p - a) @ ab) / max(float(ab @ ab), 1e-300), 0.0, 1.0)
        worst = max(worst, float(np.linalg.norm(p - (a + t[:, None] * ab), axis=1).max(initial=0.0)))
    return worst / size if size > 0 else 0.0


def _wrapped(angle: np.ndarray | float) -> np.ndarray:
    """Angles brought into (−π, π]."""
    return np.angle(np.exp(1j * np.asarray(angle, np.float64)))
