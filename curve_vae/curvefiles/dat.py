"""Airfoil coordinate files (.dat) as the UIUC database and design programs write them: Selig (a title, then x y
from the trailing edge over the upper surface to the leading edge and back) and Lednicer (a title, the two surfaces'
point counts, each surface from leading to trailing edge). Headers of any number of lines, remarks after the numbers
(`1.0 0.0013 ->1.000000 …`), notes after the coordinates (a block of polars) and Fortran exponents (1.0D-02)."""

from __future__ import annotations

import re

import numpy as np

from curve_vae.curvefiles.common import MIN_POINTS, CurveFileError, warn

_NUM = r"[+-]?(?:\d+\.?\d*|\.\d+)(?:[eEdD][+-]?\d+)?"
# Two numbers at the start of a line: apart by spaces or a comma, or abutting where the second has its sign (Fortran
# fixed columns: 0.500000-0.030000); what follows them is a remark unless it is a third number.
_PAIR = re.compile(rf"\s*({_NUM})(?:[\s,]+|(?=[+-]))({_NUM})(?![\d.])[\s,]*(.*)")
_LEADING_NUMBER = re.compile(rf"{_NUM}(?:\s|,|$)")


def _float(token: str) -> float:
    return float(token.replace("D", "E").replace("d", "e"))


def _pair(line: str) -> tuple[float, float, str] | None:
    """x, y and the remark after them, or None when the line is not one point."""
    m = _PAIR.match(line)
    if m is None or _LEADING_NUMBER.match(m[3]):
        return None
    return _float(m[1]), _float(m[2]), m[3].strip()


def _rows(text: str, name: str) -> tuple[list[tuple[int, float, float]], tuple[int, str] | None]:
    """(line number, x, y) of the coordinates, the first run of point lines, and the line that ended that run (None
    at the end of the file). The header before the run is skipped; remarks after numbers are named in a warning."""
    rows: list[tuple[int, float, float]] = []
    remarks: list[tuple[int, str]] = []
    end = None
    for number, line in enumerate(text.splitlines(), start=1):
        if not line.strip():
            continue
        point = _pair(line)
        if point is None:
            if rows:
                end = (number, line.strip())
                break
            continue  # the title and header lines
        rows.append((number, point[0], point[1]))
        if point[2]:
            remarks.append((number, point[2]))
    if remarks:
        number, remark = remarks[0]
        warn(f"{name}:{number}: remarks after the numbers skipped on {len(remarks)} line(s) ({remark[:40]!r} …)")
    return rows, end


def _lednicer(pts: np.ndarray) -> tuple[int, int] | None:
    """The two surfaces' point counts where the first row holds them (Lednicer's format)."""
    if pts[0].min() >= 2 and float(pts[0, 0]).is_integer() and float(pts[0, 1]).is_integer():
        return int(pts[0, 0]), int(pts[0, 1])
    return None


def parse_dat(text: str, name: str = "<dat>") -> np.ndarray:
    """One airfoil (n, 2) in Selig order. CurveFileError names the file and line. Lines after the coordinates (notes,
    polars) are skipped with a warning; a line that cuts them short (fewer than 4 points, or fewer than a Lednicer
    file's counts) is an error."""
    rows, end = _rows(text, name)
    if not rows:
        raise CurveFileError(f"{name}: no coordinates in this file (expected lines of two numbers x y)")
    pts = np.array([r[1:] for r in rows])
    counts = _lednicer(pts)
    wanted = 1 + sum(counts) if counts else MIN_POINTS
    if end is not None and len(pts) < wanted:
        raise CurveFileError(f"{name}:{end[0]}: expected two numbers x y, got {end[1]!r}")
    if end is not None:
        warn(f"{name}:{end[0]}: the coordinates end here; the lines from here on are skipped ({end[1][:40]!r} …)")
    if counts:
        upper, lower = counts
        if len(pts) - 1 != upper + lower:
            raise CurveFileError(
                f"{name}:{rows[0][0]}: Lednicer counts {upper} + {lower}, but {len(pts) - 1} points follow"
            )
        up, lo = pts[1 : 1 + upper], pts[1 + upper :]
        pts = np.concatenate([up[::-1], lo[1:] if np.allclose(lo[0], up[0]) else lo])
    if len(pts) < MIN_POINTS:
        raise CurveFileError(f"{name}: {len(pts)} points; a curve needs at least {MIN_POINTS}")
    return pts
