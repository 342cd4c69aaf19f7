"""Curves from text: JSON (an API body, a list of curves, one curve, the page's export) and CSV/TSV (x,y rows, a
header row naming the columns, the page's `curve,role,of,weights,index,x,y`). Where curves carry roles (a `role`
field or column), a file's inputs are its curves (roles.py)."""

from __future__ import annotations

import csv
import json
from typing import Any

import numpy as np

from curve_vae.curvefiles.common import CurveFileError, as_curves, number
from curve_vae.curvefiles.roles import Found, the_inputs

JSON_SHAPES = (
    '[[x, y], …] (one curve), [curve, …], {"curves": [curve, …]} (as the API takes them), '
    '{"curves": [{"name": …, "points": [[x, y], …]}, …]} (the page\'s export) or {"curve": …} (as /revolve takes it)'
)


def parse_json(text: str, name: str) -> list[np.ndarray]:
    """The curves of a JSON document in any of JSON_SHAPES; CurveFileError says which shapes are read."""
    try:
        data: Any = json.loads(text)
    except json.JSONDecodeError as e:
        raise CurveFileError(f"{name}:{e.lineno}: not JSON ({e.msg})") from None
    if isinstance(data, dict):
        if isinstance(data.get("curves"), list):
            data = data["curves"]
        elif "curve" in data:
            data = [data["curve"]]
        elif "points" in data:
            data = [data]
        else:
            raise CurveFileError(f"{name}: a JSON object needs a 'curves' list; the shapes read are {JSON_SHAPES}")
    if not isinstance(data, list):
        raise CurveFileError(f"{name}: JSON of curves is a list or an object; the shapes read are {JSON_SHAPES}")
    if data and isinstance(data[0], list) and data[0] and not isinstance(data[0][0], list | dict):
        data = [data]  # a single curve
    return as_curves([f.points for f in the_inputs((_found(c, i, name) for i, c in enumerate(data)), name)], name)


def _found(curve: Any, i: int, name: str) -> Found:
    """A curve of a JSON list: its points and role, from an object (the page's export), or its points as they are."""
    if isinstance(curve, dict):
        label = f" ({curve['name']})" if "name" in curve else ""
        if "points" not in curve:
            raise CurveFileError(f"{name}: curves[{i}]{label} is an object without 'points'")
        role = curve.get("role")
        return Found(f"curves[{i}]{label}", curve["points"], role if isinstance(role, str) and role else None)
    return Found(f"curves[{i}]", curve)


def _delimiter(line: str) -> str | None:
    for d in ("\t", ",", ";"):
        if d in line:
            return d
    return None  # columns apart by spaces


def _cells(line: str, delimiter: str | None) -> list[str]:
    if delimiter is None:
        return line.split()
    return [c.strip() for c in next(csv.reader([line], delimiter=delimiter))]


def _columns(header: list[str], number_line: int, name: str) -> tuple[int, int, int | None, int | None]:
    """Where x, y, the curve's name and its role are, from a header row."""
    names = [h.strip().lower() for h in header]
    curve = next((names.index(k) for k in ("curve", "name", "id") if k in names), None)
    if "x" in names and "y" in names:
        return names.index("x"), names.index("y"), curve, names.index("role") if "role" in names else None
    if len(names) == 2:
        return 0, 1, None, None
    raise CurveFileError(f"{name}:{number_line}: a header row needs columns named x and y, got {','.join(header)}")


def parse_csv(text: str, name: str) -> list[np.ndarray]:
    """Curves from CSV or TSV: one point a row. Without a header, a row is `x,y` and a blank line starts the next
    curve; with one, the columns named x and y are read and a `curve` (or `name`) column groups the rows, each
    curve's rows one after another (blank lines between them change nothing); a `role` column marks roles (a
    curve's first row says its role)."""
    lines = text.splitlines()
    first = next((i for i, line in enumerate(lines) if line.strip()), None)
    if first is None:
        raise CurveFileError(f"{name}: no curve in this file (it is empty)")
    delimiter = _delimiter(lines[first])
    cells = _cells(lines[first], delimiter)
    header = any(number(c) is None for c in cells)
    x, y, key, role = _columns(cells, first + 1, name) if header else (0, 1, None, None)
    curves: list[list[tuple[float, float]]] = [[]]
    roles: list[str | None] = [None]
    last = None
    began: dict[str, int] = {}  # each curve name's first row (1-based)
    for i in range(first + header, len(lines)):
        if not lines[i].strip():
            if key is None:  # a blank line starts the next curve; where a column names the curves, the names do
                curves.append([])
                roles.append(None)
            continue
        row = _cells(lines[i], delimiter)
        values = [number(row[j]) if j < len(row) else None for j in (x, y)]
        if values[0] is None or values[1] is None or (not header and len(row) != 2):
            what = "two numbers x,y" if not header or len(cells) == 2 else "numbers in the columns named x and y"
            raise CurveFileError(f"{name}:{i + 1}: expected {what}, got {lines[i].strip()!r}")
        if key is not None:
            if key >= len(row):
                raise CurveFileError(f"{name}:{i + 1}: no column {cells[key]!r} in {lines[i].strip()!r}")
            if row[key] != last:
                if row[key] in began:  # joined or kept apart, either guess could be wrong: the file says which
                    raise CurveFileError(
                        f"{name}:{i + 1}: curve {row[key]!r} again after other curves (its rows begin at row "
                        f"{began[row[key]]}): list each curve's rows one after another, or name the pieces apart"
                    )
                began[row[key]] = i + 1
                curves.append([])
                roles.append(None)
                last = row[key]
        if not curves[-1] and role is not None and role < len(row):
            roles[-1] = row[role] or None
        curves[-1].append((values[0], values[1]))
    found = [Found(f"row {i}", c, r) for i, (c, r) in enumerate(zip(curves, roles)) if c]
    return as_curves([f.points for f in the_inputs(found, name)], name)
