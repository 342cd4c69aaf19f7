"""A clamped cubic B-spline (the API's `splines`: control points, knots, degree) as cubic Bézier segments, exactly:
each knot span's polynomial (scipy's PPoly.from_spline) in the Bernstein basis."""

from __future__ import annotations

from typing import Any

import numpy as np

from curve_vae.curvefiles.common import CurveFileError


def spline_beziers(control_points: Any, knots: Any, degree: int = 3) -> np.ndarray:
    """The spline's cubic Bézier segments (m, 4, 2), one per knot span of positive length, in order."""
    from scipy.interpolate import BSpline, PPoly  # here, not at import: the CLI starts without scipy

    if degree != 3:
        raise CurveFileError(f"a B-spline of degree {degree}: Bézier paths are written for cubic splines only")
    t = np.asarray(knots, dtype=np.float64)
    c = np.asarray(control_points, dtype=np.float64)  # (n, 2)
    if c.ndim != 2 or c.shape[1] != 2 or len(t) != len(c) + degree + 1:
        raise CurveFileError(f"a B-spline needs n control points [x, y] and n + 4 knots, got {c.shape} and {len(t)}")
    pieces = [PPoly.from_spline(BSpline(t, c[:, j], degree)) for j in range(2)]
    a = np.stack([p.c for p in pieces], axis=-1)  # (4, spans, 2): powers 3, 2, 1, 0 of (u - u_i)
    h = np.diff(pieces[0].x)  # (spans,)
    keep = h > 0
    a, h = a[:, keep], h[keep][:, None]
    a0, a1, a2, a3 = a[3], a[2] * h, a[1] * h**2, a[0] * h**3  # each (m, 2): the span's polynomial in s ∈ [0, 1]
    return np.stack([a0, a0 + a1 / 3, a0 + (2 * a1 + a2) / 3, a0 + a1 + a2 + a3], axis=1)  # (m, 4, 2)


def bezier_points(segments: np.ndarray, per_segment: int = 16) -> np.ndarray:
    """Points along Bézier segments (m, 4, 2): each segment at `per_segment` steps, the joins once."""
    s = np.linspace(0, 1, per_segment + 1)[1:, None]  # (k, 1)
    w = np.stack([(1 - s) ** 3, 3 * s * (1 - s) ** 2, 3 * s**2 * (1 - s), s**3])  # (4, k, 1)
    pts = np.einsum("jkx,mjc->mkc", w, segments)  # (m, k, 2)
    return np.concatenate([segments[:1, 0], pts.reshape(-1, 2)])
