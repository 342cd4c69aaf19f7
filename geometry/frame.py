"""Coordinate frames and resampling: how any curve is brought to the model and back.

The model works in the paper's 128×128 plane. A caller's curve may live anywhere at any
size and have any number of points; `fit_frame` finds the similarity (shift + uniform
scale, no rotation) that maps its bounding box onto the model's, and `resample` moves it
to the model's point count by arc length. Both are exactly invertible up to float error.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: Centre of the model's plane (paper §3.1: a radius-64 circle in a 128×128 plane).
MODEL_CENTER = (64.0, 64.0)


@dataclass(frozen=True)
class Frame:
    """Where a curve lives: the centre of its bounding box and its larger side."""

    center: tuple[float, float]
    size: float

    def to_model(self, pts: np.ndarray, model_size: float) -> np.ndarray:
        """Map points of this frame into the model plane, bounding box size `model_size`."""
        c = np.asarray(self.center)
        return (np.asarray(pts, np.float64) - c) * (model_size / self.size) + np.asarray(MODEL_CENTER)

    def from_model(self, pts: np.ndarray, model_size: float) -> np.ndarray:
        """Inverse of `to_model`."""
        c = np.asarray(self.center)
        return (np.asarray(pts, np.float64) - np.asarray(MODEL_CENTER)) * (self.size / model_size) + c


def fit_frame(points: np.ndarray) -> Frame:
    """Frame of one curve (n, 2). Raises ValueError when all points coincide."""
    pts = np.asarray(points, dtype=np.float64)
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    size = float((hi - lo).max())
    if not size > 0:
        raise ValueError("all points coincide: a curve needs at least 2 distinct points")
    center = (lo + hi) / 2
    return Frame(center=(float(center[0]), float(center[1])), size=size)


def blend_frames(frames: list[Frame], weights: np.ndarray) -> list[Frame]:
    """Affine blend of frames, one per weight row: the frame an interpolant is returned in.

    weights: (rows, len(frames)), each row summing to 1.
    """
    centers = np.array([f.center for f in frames])  # (k, 2)
    sizes = np.array([f.size for f in frames])  # (k,)
    w = np.asarray(weights, dtype=np.float64)
    out_c, out_s = w @ centers, w @ sizes
    # An extrapolating row could drive the size to zero or below; keep the frame invertible.
    out_s = np.maximum(out_s, 1e-12 * sizes.max())
    return [Frame(center=(float(c[0]), float(c[1])), size=float(s)) for c, s in zip(out_c, out_s)]


def arc_fractions(points: np.ndarray) -> np.ndarray:
    """Where each point of a polyline (n, 2) sits along its arc length, from 0 to 1."""
    s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(points, axis=0), axis=1))])
    if s[-1] <= 0:
        raise ValueError("all points coincide: a curve needs at least 2 distinct points")
    return s / s[-1]


def at_fractions(curve: np.ndarray, fractions: np.ndarray) -> np.ndarray:
    """Points of a polyline (m, 2) at fractions of its index range, linearly between neighbours.

    Point j stands for fraction j/(m-1), so fractions from the same spacing give its own points.
    """
    x = np.clip(fractions, 0.0, 1.0) * (len(curve) - 1)
    idx = np.arange(len(curve))
    return np.stack([np.interp(x, idx, curve[:, 0]), np.interp(x, idx, curve[:, 1])], axis=1)


def resample(points: np.ndarray, n_points: int, *, spacing: str = "arc_length") -> np.ndarray:
    """Resample a polyline (n, 2) to n_points; end points are kept.

    spacing "arc_length": evenly along the arc (repeated points are harmless); "parameter":
    evenly along the point index, for points that are already evenly spaced in the curve's
    parameter — the data set's sampling, which arc-length spacing would move by several
    pixels where the curve's control points bunch up.
    """
    pts = np.asarray(points, dtype=np.float64)
    if spacing == "parameter":
        return pts.copy() if len(pts) == n_points else at_fractions(pts, np.linspace(0.0, 1.0, n_points))
    if spacing != "arc_length":
        raise ValueError(f"spacing must be 'arc_length' or 'parameter', got {spacing!r}")
    seg = np.linalg.norm(np.diff(pts, axis=0), axis=1)
    if len(pts) == n_points and np.ptp(seg) <= 1e-9 * max(seg.mean(), 1e-300):
        return pts.copy()  # already evenly spaced: untouched, so a round trip is exact
    s = np.concatenate([[0.0], np.cumsum(seg)])
    if s[-1] <= 0:
        raise ValueError("all points coincide: a curve needs at least 2 distinct points")
    keep = np.concatenate([[True], seg > 0])  # np.interp needs strictly increasing abscissae
    s, pts = s[keep], pts[keep]
    target = np.linspace(0.0, s[-1], n_points)
    return np.stack([np.interp(target, s, pts[:, 0]), np.interp(target, s, pts[:, 1])], axis=1)
