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


def resample(points: np.ndarray, n_points: int) -> np.ndarray:
    """Resample a polyline (n, 2) to n_points evenly spaced along its arc length.

    End points are kept; repeated consecutive points are harmless.
    """
    pts = np.asarray(points, dtype=np.float64)
    if len(pts) == n_points:
        seg = np.linalg.norm(np.diff(pts, axis=0), axis=1)
        # Already evenly spaced: return untouched so a round trip is exact.
        if np.ptp(seg) <= 1e-9 * max(seg.mean(), 1e-300):
            return pts.copy()
    seg = np.linalg.norm(np.diff(pts, axis=0), axis=1)
    s = np.concatenate([[0.0], np.cumsum(seg)])
    if s[-1] <= 0:
        raise ValueError("all points coincide: a curve needs at least 2 distinct points")
    keep = np.concatenate([[True], seg > 0])  # np.interp needs strictly increasing abscissae
    s, pts = s[keep], pts[keep]
    target = np.linspace(0.0, s[-1], n_points)
    return np.stack([np.interp(target, s, pts[:, 0]), np.interp(target, s, pts[:, 1])], axis=1)
