"""geometry.matching's placement as compiled code that releases the GIL (numba, `nogil=True`): curve by curve, each
point's nearest sample of its spline, the order-keeping dynamic programme only where those run out of order, then
the Newton polish and the running maximum — the same arithmetic as the numpy it replaces (float32 distances to the
samples, each spline evaluated by Horner's rule on its span's polynomial), so the same samples are found.
"""

from __future__ import annotations

import numpy as np

from curve_vae.geometry.natural_kernel import _compiled


@_compiled(inline="always")
def _at(
    poly: np.ndarray, spans: int, u: float, order: int, first: np.ndarray, last: np.ndarray, out: np.ndarray
) -> None:
    """A cubic spline's point at u (clipped to [0, 1]) into out[0], its first and second derivatives in u into out[1]
    and out[2] when `order` asks: Horner's rule on the span's polynomial (geometry.bspline.spline_values' own)."""
    uc = min(max(u, 0.0), 1.0)
    span = min(int(uc * spans), spans - 1)
    x = uc * spans - span
    p = poly[span]  # (powers, 2)
    fs = float(spans)
    for d in range(2):
        out[0, d] = ((p[3, d] * 1.0 * x + p[2, d] * 1.0) * x + p[1, d] * 1.0) * x + p[0, d] * 1.0
        if order >= 1:
            out[1, d] = ((p[3, d] * 3.0 * x + p[2, d] * 2.0) * x + p[1, d] * 1.0) * fs
        if order >= 2:
            out[2, d] = (p[3, d] * 6.0 * x + p[2, d] * 2.0) * fs**2
    if uc <= 0.0:  # a clamped spline passes through its end control points: there exactly
        out[0, 0], out[0, 1] = first[0], first[1]
    elif uc >= 1.0:
        out[0, 0], out[0, 1] = last[0], last[1]


@_compiled()
def _nearest(samples: np.ndarray, pts: np.ndarray, idx: np.ndarray) -> bool:
    """Each point's nearest sample into idx, the ends at the spline's ends, in float32 as the programme measures it;
    whether they run out of order anywhere."""
    n, m = len(pts), len(samples)
    tangled = False
    idx[0] = 0
    for i in range(1, n):
        if i == n - 1:
            idx[i] = m - 1
        else:
            px, py = np.float32(pts[i, 0]), np.float32(pts[i, 1])
            best = np.float32(np.inf)
            at = 0
            for j in range(m):
                dx = samples[j, 0] - px
                dy = samples[j, 1] - py
                dd = dx * dx + dy * dy
                if dd < best:
                    best = dd
                    at = j
            idx[i] = at
        if idx[i] < idx[i - 1]:
            tangled = True
    return tangled


@_compiled()
def _programme(samples: np.ndarray, pts: np.ndarray, idx: np.ndarray) -> None:
    """The order-keeping match of least total squared distance, ends to ends, into idx (a dynamic programme over
    points × samples, float32)."""
    n, m = len(pts), len(samples)
    cost = np.empty((n, m), np.float32)
    for j in range(m):
        cost[0, j] = np.float32(np.inf)
    dx = samples[0, 0] - np.float32(pts[0, 0])
    dy = samples[0, 1] - np.float32(pts[0, 1])
    cost[0, 0] = dx * dx + dy * dy
    for i in range(1, n):
        px, py = np.float32(pts[i, 0]), np.float32(pts[i, 1])
        running = np.float32(np.inf)
        for j in range(m):
            if cost[i - 1, j] < running:
                running = cost[i - 1, j]
            dx = samples[j, 0] - px
            dy = samples[j, 1] - py
            cost[i, j] = running + (dx * dx + dy * dy)
    j = m - 1
    for i in range(n - 1, 0, -1):
        idx[i] = j
        best = cost[i - 1, 0]
        at = 0
        for jj in range(1, j + 1):
            if cost[i - 1, jj] < best:
                best = cost[i - 1, jj]
                at = jj
        j = at
    idx[0] = 0


@_compiled()
def _polish(
    poly: np.ndarray,
    first: np.ndarray,
    last: np.ndarray,
    pts: np.ndarray,
    u: np.ndarray,
    step: float,
    newton: int,
    r: np.ndarray,
) -> None:
    """Newton on each inner point's squared distance from its sample's parameter u, within a sample's step either
    side, a step that takes it further not taken; the ends stay at 0 and 1. The residuals (spline - point) into r."""
    n, spans = len(pts), poly.shape[0]
    ev = np.empty((3, 2))
    lo = np.empty(n)
    hi = np.empty(n)
    t = np.empty((n, 2))
    k = np.empty((n, 2))
    for i in range(n):
        lo[i] = min(max(u[i] - step, 0.0), 1.0)
        hi[i] = min(max(u[i] + step, 0.0), 1.0)
    u[0], u[n - 1] = 0.0, 1.0
    for i in range(n):
        _at(poly, spans, u[i], 2, first, last, ev)
        r[i, 0], r[i, 1] = ev[0, 0] - pts[i, 0], ev[0, 1] - pts[i, 1]
        t[i, 0], t[i, 1], k[i, 0], k[i, 1] = ev[1, 0], ev[1, 1], ev[2, 0], ev[2, 1]
    for s in range(newton):
        order = 0 if s == newton - 1 else 2
        for i in range(1, n - 1):
            grad = r[i, 0] * t[i, 0] + r[i, 1] * t[i, 1]
            curv = (t[i, 0] * t[i, 0] + t[i, 1] * t[i, 1]) + (r[i, 0] * k[i, 0] + r[i, 1] * k[i, 1])
            moved = u[i] - (grad / curv if curv > 0 else 0.0)
            moved = min(max(moved, lo[i]), hi[i])
            _at(poly, spans, moved, order, first, last, ev)
            rx, ry = ev[0, 0] - pts[i, 0], ev[0, 1] - pts[i, 1]
            if rx * rx + ry * ry < r[i, 0] * r[i, 0] + r[i, 1] * r[i, 1]:
                u[i] = moved
                r[i, 0], r[i, 1] = rx, ry
                if order:
                    t[i, 0], t[i, 1], k[i, 0], k[i, 1] = ev[1, 0], ev[1, 1], ev[2, 0], ev[2, 1]


@_compiled()
def _in_order(
    poly: np.ndarray, first: np.ndarray, last: np.ndarray, pts: np.ndarray, u: np.ndarray, r: np.ndarray
) -> float:
    """The parameters made a running maximum (a point polished back past the one before it goes where that one is,
    its residual with it); the sum of squared residuals."""
    ev = np.empty((3, 2))
    total = 0.0
    top = -np.inf
    for i in range(len(pts)):
        if u[i] < top:
            u[i] = top
            _at(poly, poly.shape[0], u[i], 0, first, last, ev)
            r[i, 0], r[i, 1] = ev[0, 0] - pts[i, 0], ev[0, 1] - pts[i, 1]
        top = u[i]
        total += r[i, 0] * r[i, 0] + r[i, 1] * r[i, 1]
    return total


@_compiled()
def place(
    poly: np.ndarray,
    ctrl: np.ndarray,
    samples: np.ndarray,
    grid: np.ndarray,
    pts: np.ndarray,
    offsets: np.ndarray,
    newton: int,
    u_out: np.ndarray,
    distance: np.ndarray,
    programme: bool = False,
) -> None:
    """Each curve b's points pts[offsets[b]:offsets[b + 1]] placed on its cubic spline (span polynomials poly (B,
    spans, 4, 2), control points (B, n_ctrl, 2), even samples (B, m, 2) float32 at `grid`): their parameters into
    u_out (N,), the sum of squared distances into distance (B,) (geometry.matching.ordered_closest_params).
    programme: run the dynamic programme on every curve, not only where the nearest samples run out of order."""
    step = 1.0 / (samples.shape[1] - 1)
    for b in range(len(offsets) - 1):
        own = pts[offsets[b] : offsets[b + 1]]
        n = len(own)
        idx = np.empty(n, np.int64)
        if _nearest(samples[b], own, idx) or programme:
            _programme(samples[b], own, idx)
        u = np.empty(n)
        for i in range(n):
            u[i] = grid[idx[i]]
        r = np.empty((n, 2))
        first, last = ctrl[b, 0], ctrl[b, ctrl.shape[1] - 1]
        _polish(poly[b], first, last, own, u, step, newton, r)
        distance[b] = _in_order(poly[b], first, last, own, u, r)
        u_out[offsets[b] : offsets[b + 1]] = u
