"""Curve quality measures: reconstruction error, smoothness (paper §3.4), self-intersection."""

from __future__ import annotations

import numpy as np
import shapely


def mse_per_curve(target: np.ndarray, pred: np.ndarray) -> np.ndarray:
    """Paper eq. 4 per curve: mean over points and both coordinates of the squared error.

    (batch, n, 2) × 2 → (batch,). The paper's "average MSE" is the mean of this.
    """
    d = np.asarray(target, np.float64) - np.asarray(pred, np.float64)
    return np.mean(d * d, axis=(-2, -1))


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
