"""The natural-spacing fit's Levenberg–Marquardt (geometry.natural) as compiled code that releases the GIL (numba,
`nogil=True`): the same steps as the batched numpy fit, row by row, with each point's basis as its knot span and the
four cubic weights there (a dense basis row is 10 numbers of which 6 are zero), so a step's normal equations are
built from 4×4 blocks. Two threads each fitting their own request's curves run on two cores at once.

Compiled on first use (about 10 s) and cached beside this file, or in NUMBA_CACHE_DIR (the Docker images set it to
/tmp/numba-cache); where no cache can be written, each process compiles afresh.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numba as nb
import numpy as np


def _compiled(**options: Any) -> Callable[[Callable[..., Any]], Any]:
    """numba.njit without the GIL, cached where a cache can be written (numba refuses `cache=True` where none can)."""

    def compile_(fn: Callable[..., Any]) -> Any:
        try:
            return nb.njit(nogil=True, cache=True, **options)(fn)
        except RuntimeError:  # "cannot cache function ...: no locator available"
            return nb.njit(nogil=True, **options)(fn)

    return compile_


@_compiled()
def _span(t: np.ndarray, u: float, nc: int) -> int:
    """The knot span l (3 ≤ l ≤ nc − 1) with t[l] ≤ u < t[l + 1]; u = 1 in the last."""
    lo, hi = 3, nc - 1
    if u >= t[nc]:
        return hi
    while lo < hi:  # the last l with t[l] <= u
        mid = (lo + hi + 1) // 2
        if t[mid] <= u:
            lo = mid
        else:
            hi = mid - 1
    return lo


@_compiled(inline="always")
def _weights(t: np.ndarray, u: float, sp: int, b: np.ndarray, s: np.ndarray) -> None:
    """The four cubic basis values at u in span sp (control points sp − 3 … sp) into b, their slopes in u into s
    (Cox–de Boor written out for degree 3; the slopes from the quadratic basis)."""
    l1, l2, l3 = u - t[sp], u - t[sp - 1], u - t[sp - 2]  # left[1..3]
    r1, r2, r3 = t[sp + 1] - u, t[sp + 2] - u, t[sp + 3] - u  # right[1..3]
    # degree 1
    tmp = 1.0 / (r1 + l1)
    a0 = r1 * tmp
    a1 = l1 * tmp
    # degree 2
    tmp = a0 / (r1 + l2)
    q0 = r1 * tmp
    saved = l2 * tmp
    tmp = a1 / (r2 + l1)
    q1 = saved + r2 * tmp
    q2 = l1 * tmp
    # degree 3
    tmp = q0 / (r1 + l3)
    b[0] = r1 * tmp
    saved = l3 * tmp
    tmp = q1 / (r2 + l2)
    b[1] = saved + r2 * tmp
    saved = l2 * tmp
    tmp = q2 / (r3 + l1)
    b[2] = saved + r3 * tmp
    b[3] = l1 * tmp
    # N'_{i,3} = 3 N_{i,2} / (t[i+3] − t[i]) − 3 N_{i+1,2} / (t[i+4] − t[i+1]), i = sp − 3 + a; N_{sp−3,2} = 0
    d1 = t[sp + 1] - t[sp - 2]
    d2 = t[sp + 2] - t[sp - 1]
    d3 = t[sp + 3] - t[sp]
    g0 = 3.0 * q0 / d1 if d1 > 0 else 0.0
    g1 = 3.0 * q1 / d2 if d2 > 0 else 0.0
    g2 = 3.0 * q2 / d3 if d3 > 0 else 0.0
    s[0] = -g0
    s[1] = g0 - g1
    s[2] = g1 - g2
    s[3] = g2


@_compiled()
def _row_buffers(n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """A row's n points' knot spans, basis weights, their slopes and residuals (`_basis`, `_residuals`)."""
    return np.empty(n, np.int64), np.empty((n, 4)), np.empty((n, 4)), np.empty((n, 2))


@_compiled()
def _basis(t: np.ndarray, u: np.ndarray, nc: int, spans: np.ndarray, b: np.ndarray, s: np.ndarray) -> None:
    """Each parameter's (clipped to [0, 1]) knot span, four weights and their slopes into spans, b and s."""
    for i in range(len(u)):
        ui = min(max(u[i], 0.0), 1.0)
        spans[i] = _span(t, ui, nc)
        _weights(t, ui, spans[i], b[i], s[i])


@_compiled()
def _residuals(ctrl: np.ndarray, pts: np.ndarray, spans: np.ndarray, b: np.ndarray, r: np.ndarray) -> float:
    """Each point's residual r = spline − point from its basis; the cost Σ r²."""
    cost = 0.0
    for i in range(len(pts)):
        x = 0.0
        y = 0.0
        for a in range(4):
            x += b[i, a] * ctrl[spans[i] - 3 + a, 0]
            y += b[i, a] * ctrl[spans[i] - 3 + a, 1]
        r[i, 0] = x - pts[i, 0]
        r[i, 1] = y - pts[i, 1]
        cost += r[i, 0] ** 2 + r[i, 1] ** 2
    return cost


@_compiled()
def _evaluate(t, u, ctrl, pts, spans, b, s, r) -> float:
    """Each point's span, weights and slopes at u, its residual r = spline(u) − point; the cost Σ r²."""
    _basis(t, u, len(ctrl), spans, b, s)
    return _residuals(ctrl, pts, spans, b, r)


@_compiled()
def fit_start(t: np.ndarray, pts: np.ndarray, u: np.ndarray, ctrl: np.ndarray, cost: np.ndarray) -> None:
    """Each row's least-squares control points (K, nc, 2) at its parameters u (K, n) and their cost (K,)."""
    k_rows, n = u.shape
    nc = ctrl.shape[1]
    spans, b, s, r = _row_buffers(n)
    for k in range(k_rows):
        _basis(t, u[k], nc, spans, b, s)
        btb = 1e-12 * np.eye(nc)
        rhs = np.zeros((nc, 2))
        for i in range(n):
            o = spans[i] - 3
            for a in range(4):
                rhs[o + a, 0] += b[i, a] * pts[k, i, 0]
                rhs[o + a, 1] += b[i, a] * pts[k, i, 1]
                for c in range(4):
                    btb[o + a, o + c] += b[i, a] * b[i, c]
        ctrl[k] = np.linalg.solve(btb, rhs)
        cost[k] = _residuals(ctrl[k], pts[k], spans, b, r)


@_compiled()
def _normal_equations(
    ctrl: np.ndarray,
    spans: np.ndarray,
    b: np.ndarray,
    s: np.ndarray,
    r: np.ndarray,
    lam: float,
    tan: np.ndarray,
    uu: np.ndarray,
    gu: np.ndarray,
    schur: np.ndarray,
    rhs: np.ndarray,
    diag: np.ndarray,
) -> None:
    """One row's damped normal equations with each point's parameter eliminated (its Schur complement, 2nc × 2nc,
    from 4×4 blocks of the basis), into schur and rhs; each point's tangent, damped curvature term uu and gradient gu
    kept for the parameters' step (`_moved`). The ends' parameters stay where they are."""
    n, nc = len(spans), len(ctrl)
    schur[:] = 0.0
    rhs[:] = 0.0
    diag[:] = 0.0
    for i in range(n):
        o = spans[i] - 3
        tx = 0.0
        ty = 0.0
        if 0 < i < n - 1:  # the ends stay where they are
            for a in range(4):
                tx += s[i, a] * ctrl[o + a, 0]
                ty += s[i, a] * ctrl[o + a, 1]
        tan[i, 0], tan[i, 1] = tx, ty
        uu[i] = (tx * tx + ty * ty) * (1.0 + lam) + 1e-12
        gu[i] = tx * r[i, 0] + ty * r[i, 1]
        wxx = 1.0 - tx * tx / uu[i]
        wyy = 1.0 - ty * ty / uu[i]
        wxy = -tx * ty / uu[i]
        ex = r[i, 0] - tx * gu[i] / uu[i]
        ey = r[i, 1] - ty * gu[i] / uu[i]
        for a in range(4):
            ja = o + a
            diag[ja] += b[i, a] * b[i, a]
            rhs[ja] += b[i, a] * ex
            rhs[nc + ja] += b[i, a] * ey
            for c in range(4):
                bb = b[i, a] * b[i, c]
                jc = o + c
                schur[ja, jc] += bb * wxx
                schur[nc + ja, nc + jc] += bb * wyy
                schur[ja, nc + jc] += bb * wxy
                schur[nc + ja, jc] += bb * wxy
    for j in range(nc):
        schur[j, j] += lam * diag[j]
        schur[nc + j, nc + j] += lam * diag[j]
    for j in range(2 * nc):
        schur[j, j] += 1e-14


@_compiled()
def _moved(
    u: np.ndarray,
    spans: np.ndarray,
    b: np.ndarray,
    dc: np.ndarray,
    tan: np.ndarray,
    uu: np.ndarray,
    gu: np.ndarray,
    u2: np.ndarray,
) -> None:
    """The parameters after the control points' step dc (back-substituted into each point's own), clipped to [0, 1]
    and never falling, the ends at 0 and 1, into u2."""
    n, nc = len(u), len(dc) // 2
    top = 0.0
    for i in range(n):
        o = spans[i] - 3
        dx = 0.0
        dy = 0.0
        for a in range(4):
            dx += b[i, a] * dc[o + a]
            dy += b[i, a] * dc[nc + o + a]
        v = u[i] - (gu[i] - (dx * tan[i, 0] + dy * tan[i, 1])) / uu[i]
        v = min(max(v, 0.0), 1.0)
        if i > 0 and v < top:  # never falling
            v = top
        top = v
        u2[i] = v
    u2[0] = 0.0
    u2[n - 1] = 1.0


@_compiled()
def lm_steps(
    t: np.ndarray,
    pts: np.ndarray,
    u: np.ndarray,
    ctrl: np.ndarray,
    cost: np.ndarray,
    damping: np.ndarray,
    steps: int,
) -> None:
    """`steps` Levenberg–Marquardt steps on every row, in place: parameters u (K, n), control points (K, nc, 2),
    cost (K,), damping (K,). A row whose damping passed 1e8 has stopped; a step is kept only where it brings the
    spline closer (geometry.natural._BatchFit.run says each term)."""
    k_rows, n = u.shape
    nc = ctrl.shape[1]
    spans, b, s, r = _row_buffers(n)
    spans2, b2, s2, r2 = _row_buffers(n)  # a step's, kept where it brings the spline closer
    tan = np.empty((n, 2))
    uu = np.empty(n)
    gu = np.empty(n)
    u2 = np.empty(n)
    schur = np.empty((2 * nc, 2 * nc))
    rhs = np.empty(2 * nc)
    diag = np.empty(nc)
    ctrl2 = np.empty((nc, 2))
    for k in range(k_rows):
        _evaluate(t, u[k], ctrl[k], pts[k], spans, b, s, r)
        for _ in range(steps):
            lam = damping[k]
            if lam > 1e8:
                break
            _normal_equations(ctrl[k], spans, b, s, r, lam, tan, uu, gu, schur, rhs, diag)
            dc = np.linalg.solve(schur, rhs)
            for j in range(nc):
                ctrl2[j, 0] = ctrl[k, j, 0] - dc[j]
                ctrl2[j, 1] = ctrl[k, j, 1] - dc[nc + j]
            _moved(u[k], spans, b, dc, tan, uu, gu, u2)
            cost2 = _evaluate(t, u2, ctrl2, pts[k], spans2, b2, s2, r2)
            if cost2 < cost[k]:  # kept: the step's basis becomes the row's
                u[k, :] = u2
                ctrl[k, :, :] = ctrl2
                cost[k] = cost2
                spans[:] = spans2
                b[:] = b2
                s[:] = s2
                r[:] = r2
                damping[k] = max(lam / 3.0, 1e-9)
            else:
                damping[k] = lam * 4.0


@_compiled()
def weights_at(t: np.ndarray, u: np.ndarray, nc: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Each parameter's knot span (m,), its four basis values and slopes (m, 4): the kernel's basis, for checks."""
    spans = np.empty(len(u), np.int64)
    b = np.empty((len(u), 4))
    s = np.empty((len(u), 4))
    for i in range(len(u)):
        ui = min(max(u[i], 0.0), 1.0)
        spans[i] = _span(t, ui, nc)
        _weights(t, ui, spans[i], b[i], s[i])
    return spans, b, s
