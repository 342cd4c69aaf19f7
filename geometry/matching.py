"""Where a curve's points sit on a B-spline that approximates it: each point matched to a point of the spline, in
order, so that the matched points are as close as they can be without stepping back along the spline.

A reconstruction is returned at the caller's own points: point i of the caller's curve comes back as its match on
the decoded spline. Matching each point to its nearest spline point alone would let a point jump to another branch
where a curve comes back near itself (an airfoil's trailing edge, a spiral's turns), and points around a corner
sharper than the spline's would pile onto its rounded tip out of order. `ordered_closest_params` matches each curve's
points to dense samples of its spline: each point's nearest sample where those run in order (ends at the ends: no
order-keeping match can be closer), else the order-keeping match of least total squared distance by dynamic
programming; then it polishes each parameter by Newton steps between its neighbours' samples. Compiled, without the
GIL (geometry.matching_kernel).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from curve_vae.errors import InvalidInput
from curve_vae.geometry.bspline import sample_bspline, span_polynomials_of
from curve_vae.geometry.matching_kernel import place

#: Samples of each spline the match runs over: about 9 per knot span of the shipped 31-point head.
DENSE = 257


def ordered_closest_params(
    control_points: np.ndarray,
    points: Sequence[np.ndarray],
    *,
    degree: int = 3,
    dense: int = DENSE,
    newton: int = 3,
    programme: bool = False,
) -> tuple[list[np.ndarray], np.ndarray]:
    """For each clamped uniform cubic B-spline (B, n_ctrl, 2) and its curve's points (n_i, 2): the parameter in [0, 1]
    of each point's match, non-decreasing, the first point at 0 and the last at 1 (the ends are the ends); and (B,)
    the sum of squared distances from each curve's points to their matches.

    The match is the order-keeping one of least total squared distance among `dense` even samples of the spline,
    then each inner point's parameter is moved by `newton` Newton steps on its squared distance, within the
    samples on either side of its match (a step that takes the point further is not taken), and kept in order.
    `programme`: the dynamic programme on every curve, not only where the nearest samples run out of order (the
    same answer: a check).
    """
    if degree != 3:
        raise InvalidInput(f"placement on a spline supports cubic splines (degree 3), got degree {degree}")
    ctrl = np.ascontiguousarray(control_points, np.float64)
    count = len(points)
    if count == 0:
        return [], np.zeros(0)
    flat = np.ascontiguousarray(np.concatenate([np.asarray(p, np.float64) for p in points]))
    offsets = np.concatenate([[0], np.cumsum([len(p) for p in points])]).astype(np.int64)
    samples = np.ascontiguousarray(sample_bspline(ctrl, dense, degree), np.float32)
    u, distance = np.empty(len(flat)), np.empty(count)
    place(span_polynomials_of(ctrl, degree), ctrl, samples, np.linspace(0.0, 1.0, dense), flat, offsets, newton, u,
          distance, programme)  # fmt: skip
    return np.split(u, offsets[1:-1]), distance
