"""What a call takes as curves: a batch, or one curve, which is sent as a batch of one.

One curve is an (n, 2) array of numbers with n ≥ 1 — a numpy array (`np.c_[x, y]`), anything numpy reads as one
(a DataFrame of x and y, a tensor), or a sequence of [x, y] pairs. A batch is a (B, n, 2) array or a sequence of
curves (of any lengths). The two never look alike: a batch's first item is a curve (the service takes curves of
≥ 4 points), one curve's first item is a point, two numbers. Endpoints that mix curves (interpolate, augment) need
at least two, so one curve there is refused here, before anything is sent.
"""

from __future__ import annotations

import numbers
from collections.abc import Sequence
from typing import Any, TypeAlias

import numpy as np

from curve_vae.errors import InvalidInput

#: What a `curves` argument takes: a batch of curves, or one curve (the module docstring says which is which).
CurvesLike: TypeAlias = Any

NUMBER_KINDS = "biuf"  # numpy's bool, integer, unsigned and float kinds


def _is_point(p: Any) -> bool:
    """Two numbers: an [x, y] pair."""
    if isinstance(p, np.ndarray):
        return p.shape == (2,) and p.dtype.kind in NUMBER_KINDS
    if isinstance(p, (str, bytes)) or not isinstance(p, Sequence):
        return False
    return len(p) == 2 and all(isinstance(v, numbers.Real) for v in p)


def as_array_like(curves: Any) -> Any:
    """`curves` itself, or the array of something numpy reads as one that is neither a sequence nor an array (a
    DataFrame, a tensor): its shape then says what it is."""
    if isinstance(curves, (np.ndarray, Sequence)) or not hasattr(curves, "__array__"):
        return curves
    return np.asarray(curves)


def is_one_curve(curves: Any) -> bool:
    """Whether `curves` is one curve (see the module docstring), not a batch of them."""
    if isinstance(curves, np.ndarray):
        return curves.ndim == 2 and curves.shape[1] == 2 and len(curves) >= 1 and curves.dtype.kind in NUMBER_KINDS
    if isinstance(curves, (str, bytes)) or not isinstance(curves, Sequence) or not len(curves):
        return False
    return _is_point(curves[0])


def as_batch(curves: Any, method: str, *, at_least: int = 1) -> Sequence[Any]:
    """The curves of a call as a batch: one curve as a batch of one. A method that mixes curves (`at_least` 2)
    refuses one curve, naming itself and what it needs."""
    curves = as_array_like(curves)
    if not is_one_curve(curves):
        return curves
    if at_least > 1:
        raise InvalidInput(
            f"{method} needs at least {at_least} curves, got one curve ({len(curves)} [x, y] points): "
            "pass a list of curves, [a, b, …]"
        )
    return [curves]
