"""Curve quality measures: reconstruction error, smoothness (paper §3.4), self-intersection."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import shapely


def mse_per_curve(target: np.ndarray, pred: np.ndarray) -> np.ndarray:
    """Paper eq. 4 per curve: mean over points and both coordinates of the squared error.

    (batch, n, 2) × 2 → (batch,). The paper's "average MSE" is the mean of this.
    """
    d = np.asarray(target, np.float64) - np.asarray(pred, np.float64)
    return np.mean(d * d, axis=(-2, -1))


def diagonal(points: np.ndarray) -> np.ndarray:
    """The bounding-box diagonal of (…, n, 2) points, over their n: the size every relative figure of a curve is
    divided by (`closeness`, the reader's "close enough", a morph's drift, a spline fit's tolerance). A float array:
    () for one curve, (B,) for a stack."""
    extent = np.ptp(np.asarray(points, np.float64), axis=-2)
    return np.hypot(extent[..., 0], extent[..., 1])


def closeness(inputs: Sequence[np.ndarray], outputs: Sequence[np.ndarray]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """How close each output came to its input, point for point, relative to the input's size: the RMS distance and
    the largest distance, each ÷ the input's bounding-box diagonal, and the index of that farthest point; three (B,)
    arrays for B curves of any lengths (outputs at their inputs' points). Unitless, so an airfoil of chord 1 and a
    stroke 800 pixels long read alike (scipy's OptimizeResult and sklearn's `score` in spirit: a figure that needs no
    context). A curve whose points all coincide has no size: its figures are inf where it has an error, else 0."""
    if not len(inputs):
        return np.zeros(0), np.zeros(0), np.zeros(0, np.int64)
    a = np.concatenate([np.asarray(c, np.float64).reshape(-1, 2) for c in inputs])
    b = np.concatenate([np.asarray(c, np.float64).reshape(-1, 2) for c in outputs])
    lengths = np.array([len(c) for c in inputs])
    if len(b) != len(a) or any(len(o) != n for o, n in zip(outputs, lengths)):
        raise ValueError("closeness compares each output at its input's points: the lengths differ")
    starts = np.concatenate([[0], np.cumsum(lengths)[:-1]])
    diag = np.hypot(*(np.maximum.reduceat(a, starts) - np.minimum.reduceat(a, starts)).T)
    d = np.hypot(*(a - b).T)
    rms = np.sqrt(np.add.reduceat(d * d, starts) / lengths)
    owner = np.repeat(np.arange(len(lengths)), lengths)
    # the farthest point of each curve: the last index of the sorted (owner, distance) pairs within each curve
    order = np.lexsort((d, owner))
    last = order[starts + lengths - 1]
    worst = d[last]
    with np.errstate(divide="ignore", invalid="ignore"):
        return (
            np.where(rms > 0, rms / diag, 0.0),
            np.where(worst > 0, worst / diag, 0.0),
            last - starts,
        )


def closest_squared_distances(points: np.ndarray, curve: np.ndarray) -> np.ndarray:
    """Each of `points` (n, 2)'s squared distance to its closest point on the polyline `curve` (m, 2), the first and
    last points to the curve's first and last points (a reconstruction's ends are the input's): (n,). How the service
    picks the pose of a model placed "closest" (training's match "closest" measures the same, in torch)."""
    pts, line = np.asarray(points, np.float64), np.asarray(curve, np.float64)
    d = shapely.distance(shapely.points(pts[1:-1]), shapely.linestrings(line)) ** 2
    ends = ((pts[[0, -1]] - line[[0, -1]]) ** 2).sum(-1)
    return np.concatenate([ends[:1], d, ends[1:]])


def turning_angles(curves: np.ndarray) -> np.ndarray:
    """Angle (radians) between consecutive unit tangents t_i = (p_{i+1}-p_i)/|·| (paper eq. 8).

    (..., n, 2) → (..., n-2). Zero-length segments count as no turn.
    """
    d = np.diff(np.asarray(curves, np.float64), axis=-2)
    norm = np.linalg.norm(d, axis=-1, keepdims=True)
    t = np.divide(d, norm, out=np.zeros_like(d), where=norm > 0)
    cross = t[..., :-1, 0] * t[..., 1:, 1] - t[..., :-1, 1] * t[..., 1:, 0]
    dot = np.sum(t[..., :-1, :] * t[..., 1:, :], axis=-1)
    return np.abs(np.arctan2(cross, dot))


def smoothness(curves: np.ndarray) -> dict[str, np.ndarray]:
    """Tangent-based smoothness of each curve (paper §3.4), in degrees.

    - mean_turn: mean angle between consecutive tangents (how much the curve bends);
    - max_turn: the sharpest corner;
    - roughness: mean |change of turning angle| between neighbours: near 0 for a smooth
      curve, large when tangents jitter (the noise the Laplacian loss removes).
    """
    a = np.degrees(turning_angles(curves))
    return {
        "mean_turn": a.mean(axis=-1),
        "max_turn": a.max(axis=-1),
        "roughness": np.abs(np.diff(a, axis=-1)).mean(axis=-1),
    }


def curve_length(curves: np.ndarray) -> np.ndarray:
    """Polyline length, (..., n, 2) → (...)."""
    return np.linalg.norm(np.diff(np.asarray(curves, np.float64), axis=-2), axis=-1).sum(axis=-1)


def self_intersects(curves: np.ndarray) -> np.ndarray | bool:
    """Whether each open polyline crosses or touches itself, (batch, n, 2) → (batch,) bool; one polyline (n, 2) → a
    bool."""
    c = np.asarray(curves, np.float64)
    if c.ndim == 2:
        return bool(~shapely.is_simple(shapely.linestrings(c)))
    return ~shapely.is_simple(shapely.linestrings(c))
