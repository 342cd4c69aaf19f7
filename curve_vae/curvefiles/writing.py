"""A command's output by the file's extension: .json (the endpoint's answer; the default, and `-` for standard
output), .csv (the points, `curve,index,x,y`), .npy (the curves as one float32 array), .svg (a path per curve; a
B-spline as exact cubic Béziers), .dxf (a SPLINE per B-spline, or an LWPOLYLINE per curve). Given marks (each curve's
role, name, `of` and `weights`: roles.py), CSV, SVG and DXF say them as the page's exports do. Every file is written
beside its name and renamed over it when complete."""

from __future__ import annotations

import json
import sys
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

from curve_vae.curvefiles.bezier import spline_beziers
from curve_vae.curvefiles.common import CurveFileError
from curve_vae.files import atomic_path, atomic_write_text


def _splines(payload: Mapping[str, Any]) -> list[dict[str, Any] | None] | None:
    """The B-splines of an answer: `splines` (--output-as bspline or both) or `fits` (curve-vae fit); a drawing's
    entries are None for its curves of points."""
    return payload.get("splines") or payload.get("fits")


def _points(payload: Mapping[str, Any], path: str, array_key: str | None) -> list[Any]:
    key = array_key or "curves"
    if key not in payload:
        hint = " (ask for points: --output-as points or both)" if _splines(payload) else ""
        raise CurveFileError(f"{path}: this output holds no curves' points to write as {Path(path).suffix}{hint}")
    return payload[key]


def write_output(
    path: str, payload: Mapping[str, Any], array_key: str | None = None, marks: list[Mapping[str, Any]] | None = None
) -> None:
    """`payload` (an endpoint's JSON answer) to `path` in the format its extension names; `marks`, one a curve, say
    each curve's role, name, input (`of`) and weights in CSV, SVG and DXF."""
    suffix = Path(path).suffix.lower() if path != "-" else ".json"
    if suffix == ".npy":
        try:
            arr = np.asarray(_points(payload, path, array_key), dtype=np.float32)
        except ValueError:
            raise CurveFileError(f"{path}: curves of different lengths fit no array; write .json or .csv") from None
        with atomic_path(path) as tmp, open(tmp, "wb") as f:
            np.save(f, arr)
    elif suffix == ".csv":
        atomic_write_text(path, _csv(_points(payload, path, array_key), marks))
    elif suffix in (".svg", ".dxf"):
        _write_drawing(path, suffix, payload, array_key, marks)
    else:
        text = json.dumps(payload, indent=None, separators=(",", ":"), default=_listed) + "\n"
        if path == "-":
            sys.stdout.write(text)
        else:
            atomic_write_text(path, text)


def _listed(value: Any) -> Any:
    """numpy in an endpoint's body (inference.results keeps arrays for the service's orjson) as lists and numbers."""
    if isinstance(value, np.ndarray | np.generic):
        return value.tolist()
    raise TypeError(f"{type(value).__name__} is not JSON serialisable")


def _csv(curves: list[Any], marks: list[Mapping[str, Any]] | None) -> str:
    """`curve,index,x,y` rows, or with marks `curve,role,of,weights,index,x,y` (a curve named by its mark)."""
    from curve_vae.curvefiles.svg import weights_text

    rows = ["curve,role,of,weights,index,x,y" if marks else "curve,index,x,y"]
    for i, c in enumerate(curves):
        key = str(i)
        if marks:
            m = marks[i]
            cells = (str(m.get("name", i)), m["role"], str(m.get("of") or ""), weights_text(m.get("weights") or {}))
            key = ",".join(_cell(v) for v in cells)
        rows += [f"{key},{j},{x!r},{y!r}" for j, (x, y) in enumerate(np.asarray(c, dtype=np.float64).tolist())]
    return "\n".join(rows) + "\n"


def _cell(text: str) -> str:
    """A CSV cell, quoted where it holds a comma or a quote."""
    return f'"{text.replace(chr(34), chr(34) * 2)}"' if any(c in text for c in ',"') else text


def _write_drawing(
    path: str, suffix: str, payload: Mapping[str, Any], array_key: str | None, marks: list[Mapping[str, Any]] | None
) -> None:
    from curve_vae.curvefiles.dxf import write_dxf
    from curve_vae.curvefiles.svg import svg_text

    splines = _splines(payload)  # where some entries are None (a drawing's inputs), those curves are points
    points_needed = not splines or any(s is None for s in splines)
    curves = [np.asarray(c, dtype=np.float64) for c in _points(payload, path, array_key)] if points_needed else None
    if suffix == ".svg":
        if splines:
            paths = [
                spline_beziers(s["control_points"], s["knots"], s["degree"]) if s is not None else (curves or [])[i]
                for i, s in enumerate(splines)
            ]
            text = svg_text(paths, beziers=[s is not None for s in splines], marks=marks)
        else:
            text = svg_text(curves or [], beziers=False, marks=marks)
        atomic_write_text(path, text)
    else:
        with atomic_path(path) as tmp:
            write_dxf(tmp, splines=splines, curves=curves, marks=marks)
