"""What every reader shares: the error and warning a file gets, numbers as coordinate files write them, and the
check that makes a list of arrays a list of curves."""

from __future__ import annotations

import re
import warnings
from collections.abc import Iterable, Sequence
from typing import Any

import numpy as np

from curve_vae.errors import InvalidInput

#: Fewest points of a curve: what the service takes (four [x, y] pairs).
MIN_POINTS = 4


class CurveFileError(InvalidInput):
    """A curve file that cannot be read; the message names the file, and the line or element where it helps."""


class CurveFileWarning(UserWarning):
    """Something in a curve file that was skipped (notes after an airfoil's coordinates, a two-point line)."""


def warn(message: str) -> None:
    warnings.warn(CurveFileWarning(message), stacklevel=3)


# A decimal number as coordinate files write it, Fortran's D exponent included (1.0D-02).
_NUMBER = re.compile(r"[+-]?(?:\d+\.?\d*|\.\d+)(?:[eEdD][+-]?\d+)?")


def number(token: str) -> float | None:
    """The value of one token, or None when it is not a number."""
    token = token.strip()
    if not _NUMBER.fullmatch(token):
        return None
    return float(token.replace("D", "E").replace("d", "e"))


def as_curves(data: Any, name: str) -> list[np.ndarray]:
    """Arrays (n, 2) of finite floats with at least MIN_POINTS points each, or CurveFileError naming the curve."""
    curves = []
    for i, c in enumerate(data):
        try:
            arr = np.asarray(c, dtype=np.float64)
        except (TypeError, ValueError):
            raise CurveFileError(f"{name}: curve {i} must be a list of [x, y] pairs of numbers") from None
        if arr.ndim != 2 or arr.shape[1] != 2:
            raise CurveFileError(f"{name}: curve {i} must be a list of [x, y] pairs, got shape {arr.shape}")
        if not np.isfinite(arr).all():
            j = int(np.argwhere(~np.isfinite(arr))[0][0])
            raise CurveFileError(f"{name}: curve {i} point {j} is not finite")
        if len(arr) < MIN_POINTS:
            raise CurveFileError(f"{name}: curve {i} has {len(arr)} points; a curve needs at least {MIN_POINTS}")
        curves.append(arr)
    if not curves:
        raise CurveFileError(f"{name}: no curve in this file")
    return curves


def drawn_curves(found: Iterable[Sequence[Any]], name: str, *, kinds: str) -> list[np.ndarray]:
    """The curves of a drawing (SVG, DXF) from its (label, points, …) entities: one of fewer than MIN_POINTS points is
    skipped with a warning naming it; a drawing with none left is a CurveFileError saying which `kinds` count."""
    curves = []
    for label, pts, *_ in found:
        if len(pts) < MIN_POINTS:
            warn(f"{name}: {label}: {len(pts)} points, not a curve; skipped")
            continue
        curves.append(pts)
    if not curves:
        raise CurveFileError(f"{name}: no curve in this drawing (no {kinds})")
    return as_curves(curves, name)
