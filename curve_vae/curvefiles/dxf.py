"""DXF in and out (ezdxf). In: the model space's LWPOLYLINE and POLYLINE entities (their vertices; bulges as arcs)
and SPLINEs (sampled along their parameter), x and y, those of inserted blocks where the INSERT puts them. Out: a
B-spline as a SPLINE entity with its control points and knots exactly, points as an LWPOLYLINE."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import ezdxf
import numpy as np
from ezdxf import path as dxfpath
from ezdxf.disassemble import recursive_decompose

from curve_vae.curvefiles.common import CurveFileError, drawn_curves

KINDS = ("LWPOLYLINE", "POLYLINE", "SPLINE")
#: Points along a SPLINE per control point (at least 64 in all).
SAMPLES_PER_CONTROL_POINT = 8


def read_dxf(path: str | Path, name: str) -> list[np.ndarray]:
    """The curves of a DXF drawing's model space, in the order they are stored."""
    try:
        doc = ezdxf.readfile(str(path))
    except (OSError, ezdxf.DXFError) as err:
        raise CurveFileError(f"{name}: not a DXF drawing ({err})") from None
    found = (
        (f"{e.dxftype()} #{e.dxf.handle}" if e.dxf.handle else f"{e.dxftype()} of a block", _points(e))
        for e in recursive_decompose(doc.modelspace())  # blocks' entities where they are inserted, transformed
        if e.dxftype() in KINDS
    )
    return drawn_curves(found, name, kinds="LWPOLYLINE, POLYLINE or SPLINE of 4 points")


def _points(e: Any) -> np.ndarray:
    kind = e.dxftype()
    if kind == "SPLINE":
        tool = e.construction_tool()
        n = max(64, SAMPLES_PER_CONTROL_POINT * len(tool.control_points))
        return np.array([(v.x, v.y) for v in tool.approximate(segments=n - 1)])
    if kind == "LWPOLYLINE" and any(b for *_, b in e.get_points("xyb")):
        p = dxfpath.make_path(e)
        size = max(p.bbox().size.x, p.bbox().size.y, 1e-12)
        return np.array([(v.x, v.y) for v in p.flattening(distance=size * 1e-4)])
    if kind == "LWPOLYLINE":
        pts = np.array([(x, y) for x, y in e.get_points("xy")], dtype=np.float64)
        closed = e.closed
    else:
        pts = np.array([(v.x, v.y) for v in e.points()], dtype=np.float64)
        closed = e.is_closed
    if closed and len(pts) and not np.array_equal(pts[0], pts[-1]):
        pts = np.vstack([pts, pts[:1]])  # a closed polyline is a loop: it ends where it starts
    return pts


def write_dxf(target: Path, *, splines: list[dict[str, Any]] | None, curves: list[np.ndarray] | None) -> None:
    """A DXF (R2010) with a SPLINE per B-spline, or else an LWPOLYLINE per curve."""
    doc = ezdxf.new("R2010")
    msp = doc.modelspace()
    for s in splines or []:
        msp.add_open_spline(
            [(float(x), float(y), 0.0) for x, y in s["control_points"]], degree=int(s["degree"]), knots=s["knots"]
        )
    if splines is None:
        for c in curves or []:
            msp.add_lwpolyline([(float(x), float(y)) for x, y in c], format="xy")
    doc.saveas(target)
