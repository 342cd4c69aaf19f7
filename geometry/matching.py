"""Where a curve's points sit on a B-spline that approximates it: each point matched to a point of the spline, in
order, so that the matched points are as close as they can be without stepping back along the spline.

A reconstruction is returned at the caller's own points: point i of the caller's curve comes back as its match on
the decoded spline. Matching each point to its nearest spline point alone would let a point jump to another branch
where a curve comes back near itself (an airfoil's trailing edge, a spiral's turns), and points around a corner
sharper than the spline's would pile onto its rounded tip out of order. `ordered_closest_params` matches all points
of a batch of curves at once by dynamic programming over dense samples of each spline (the order-keeping match of
least total squared distance, ends to ends), then polishes each parameter by Newton steps between its neighbours'.
Pure numpy; a batch costs a few array operations per point of the longest curve.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from curve_vae.geometry.bspline import sample_bspline, spline_values

#: Samples of each spline the match runs over: about 9 per knot span of the shipped 31-point head.
DENSE = 257
#: Elements (curves × points × samples) one pass of the match holds at once (float32: ~8 MB an array). A 128-curve
#: default request's two candidates a curve in chunks of 8,000,000 cost 1,301 and 1,297 ms CPU, of 2,000,000 1,255 and
#: 1,250 (interleaved in one process): fresh pages cost more than the extra passes.
CHUNK_ELEMENTS = 2_000_000


def ordered_closest_params(
    control_points: np.ndarray,
    points: Sequence[np.ndarray],
    *,
    degree: int = 3,
    dense: int = DENSE,
    newton: int = 3,
) -> tuple[list[np.ndarray], np.ndarray]:
    """For each clamped uniform B-spline (B, n_ctrl, 2) and its curve's points (n_i, 2): the parameter in [0, 1] of
    each point's match, non-decreasing, the first point at 0 and the last at 1 (the ends are the ends); and (B,)
    the sum of squared distances from each curve's points to their matches.

    The match is the order-keeping one of least total squared distance among `dense` even samples of the spline,
    then each inner point's parameter is moved by `newton` Newton steps on its squared distance, within the
    samples on either side of its match (a step that takes the point further is not taken), and kept in order.
    """
    ctrl = np.asarray(control_points, np.float64)
    count = len(points)
    if count == 0:
        return [], np.zeros(0)
    lengths = np.array([len(p) for p in points])
    params = _sample_matches(ctrl, points, lengths, degree=degree, dense=dense)
    flat_u = np.concatenate(params)
    owner = np.repeat(np.arange(count), lengths)
    flat_p = np.concatenate([np.asarray(p, np.float64) for p in points])
    step = 1.0 / (dense - 1)
    lo, hi = np.clip(flat_u - step, 0.0, 1.0), np.clip(flat_u + step, 0.0, 1.0)
    inner = np.ones(len(flat_u), bool)
    ends = np.concatenate([[0], np.cumsum(lengths)])
    inner[ends[:-1]] = inner[ends[1:] - 1] = False
    flat_u[ends[:-1]], flat_u[ends[1:] - 1] = 0.0, 1.0

    def at(u: np.ndarray, order: int = 0) -> list[np.ndarray]:
        return spline_values(ctrl, u, owner, degree=degree, order=order)

    value, t, k = at(flat_u, 2)
    r = value - flat_p
    for step in range(newton):
        grad, curv = (r * t).sum(-1), (t * t).sum(-1) + (r * k).sum(-1)
        moved = np.clip(flat_u - np.where(curv > 0, grad / np.where(curv > 0, curv, 1.0), 0.0), lo, hi)
        moved = np.where(inner, moved, flat_u)
        last = step == newton - 1  # the next step's slope and curvature too, where there is a next step
        value, *slopes = at(moved, 0 if last else 2)
        r_moved = value - flat_p
        closer = ((r_moved**2).sum(-1) < (r**2).sum(-1))[:, None]
        flat_u = np.where(closer[:, 0], moved, flat_u)
        r = np.where(closer, r_moved, r)
        if not last:
            t, k = np.where(closer, slopes[0], t), np.where(closer, slopes[1], k)
    if (lengths == lengths[0]).all():  # in order within each curve: a running maximum along each
        ordered = np.maximum.accumulate(flat_u.reshape(count, -1), axis=1).ravel()
    else:
        ordered = np.concatenate([np.maximum.accumulate(flat_u[a:b]) for a, b in zip(ends[:-1], ends[1:])])
    if not np.array_equal(ordered, flat_u):
        r = at(ordered)[0] - flat_p
    out = np.split(ordered, ends[1:-1])
    distance = np.bincount(owner, weights=(r**2).sum(-1), minlength=count)
    return out, distance


def _sample_matches(
    ctrl: np.ndarray, points: Sequence[np.ndarray], lengths: np.ndarray, *, degree: int, dense: int
) -> list[np.ndarray]:
    """Each curve's points matched to `dense` even samples of its spline (`_ordered_nearest`): their parameters,
    curves of similar length run together in chunks of at most CHUNK_ELEMENTS (padding repeats the last point)."""
    count = len(points)
    samples = sample_bspline(ctrl, dense, degree)  # (B, m, 2)
    grid = np.linspace(0.0, 1.0, dense)
    params: list[np.ndarray] = [np.empty(0)] * count
    order = np.argsort(lengths, kind="stable")
    start = 0
    while start < count:
        stop = start + 1
        while stop < count and (stop - start + 1) * lengths[order[stop]] * dense <= CHUNK_ELEMENTS:
            stop += 1
        idx = order[start:stop]
        longest = int(lengths[idx].max())
        padded = np.stack([_padded(np.asarray(points[i], np.float64), longest) for i in idx])
        sample_idx = _ordered_nearest(padded, samples[idx].astype(np.float32), lengths[idx])
        for row, i in enumerate(idx):
            params[i] = grid[sample_idx[row, : lengths[i]]]
        start = stop
    return params


def _padded(points: np.ndarray, length: int) -> np.ndarray:
    """(length, 2): the points, then their last point repeated (a repeated end matches the spline's end)."""
    return np.concatenate([points, np.repeat(points[-1:], length - len(points), axis=0)])


def _ordered_nearest(points: np.ndarray, samples: np.ndarray, lengths: np.ndarray) -> np.ndarray:
    """`_match`'s answer, found the quick way where it can be: each inner point's nearest sample, for all points of all
    curves in one array operation. Where those indices already run in order (ends at the ends), no order-keeping
    assignment can be closer, so they are the match; the dynamic programme runs only on the curves where they do not
    (a curve that comes back near itself, a corner sharper than the spline's)."""
    b, n, _ = points.shape
    m = samples.shape[1]
    p = points.astype(np.float32)
    # the squared distances as _match computes them (float32, x and y apart), so that both find the same samples
    dx = samples[:, None, :, 0] - p[:, :, None, 0]  # (b, n, m)
    dy = samples[:, None, :, 1] - p[:, :, None, 1]
    np.multiply(dx, dx, out=dx)
    np.multiply(dy, dy, out=dy)
    out = np.add(dx, dy, out=dx).argmin(axis=2)
    out[:, 0] = 0
    out[np.arange(n)[None, :] >= (lengths - 1)[:, None]] = m - 1  # each curve's last point and its padding: the end
    tangled = (np.diff(out, axis=1) < 0).any(axis=1)
    if tangled.any():
        out[tangled] = _match(points[tangled], samples[tangled], lengths[tangled])
    return out


def _match(points: np.ndarray, samples: np.ndarray, lengths: np.ndarray) -> np.ndarray:
    """(B, n) sample index of each point (B, n, 2) among the samples (B, m, 2): the non-decreasing assignment of
    least total squared distance, first point to sample 0 and each curve's last real point (lengths) to m − 1."""
    b, n, _ = points.shape
    m = samples.shape[1]
    px, py = points[..., 0].astype(np.float32), points[..., 1].astype(np.float32)
    sx, sy = np.ascontiguousarray(samples[..., 0]), np.ascontiguousarray(samples[..., 1])
    cost = np.empty((n, b, m), np.float32)  # cost[i, :, j]: the best match of points 0..i with point i at sample j
    cost[0] = np.inf
    cost[0, :, 0] = (px[:, 0] - sx[:, 0]) ** 2 + (py[:, 0] - sy[:, 0]) ** 2
    dx, dy = np.empty((b, m), np.float32), np.empty((b, m), np.float32)
    for i in range(1, n):
        np.subtract(sx, px[:, i, None], out=dx)
        np.subtract(sy, py[:, i, None], out=dy)
        np.multiply(dx, dx, out=dx)
        np.multiply(dy, dy, out=dy)
        np.add(dx, dy, out=dx)
        np.minimum.accumulate(cost[i - 1], axis=1, out=cost[i])
        cost[i] += dx
    j = np.full(b, m - 1)
    out = np.empty((b, n), np.int64)
    later = np.empty((b, m), bool)  # reused: which samples lie beyond each curve's current match
    last = lengths - 1
    for i in range(n - 1, 0, -1):
        out[:, i] = j
        np.greater(np.arange(m)[None, :], j[:, None], out=later)
        prev = np.where(later, np.inf, cost[i - 1]).argmin(axis=1)
        # at a curve's last real point and beyond it (padding), the match stays at the spline's end
        j = np.where(i - 1 >= last, m - 1, prev)
    out[:, 0] = 0
    return out
