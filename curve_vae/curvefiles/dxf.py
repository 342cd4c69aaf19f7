"""DXF in and out (ezdxf). In: the model space's LWPOLYLINE and POLYLINE entities (their vertices; bulges as arcs)
and SPLINEs (sampled along their parameter), x and y, those of inserted blocks where the INSERT puts them; an
entity's role (roles.py) is in its XDATA (application CURVE_VAE: `role=…`, `name=…`, `of=…`, `weights=A=0.75 B=0.25`,
one string each) or else its layer's first word (`input-A`, `reconstruction-A`, `interpolant-mix`). Out: a B-spline as
a SPLINE entity with its control points and knots exactly, points as an LWPOLYLINE; given marks, each on the layer
`<role>-<name>` with that XDATA."""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

import ezdxf
import numpy as np
from ezdxf import path as dxfpath
from ezdxf.disassemble import recursive_decompose
from ezdxf.entities import DXFGraphic

from curve_vae.curvefiles.common import CurveFileError, drawn_curves
from curve_vae.curvefiles.roles import INTERPOLANT_ACI, PALETTE_ACI, ROLES, Found, colour_index, the_inputs
from curve_vae.curvefiles.svg import weights_text

KINDS = ("LWPOLYLINE", "POLYLINE", "SPLINE")
#: Points along a SPLINE per control point (at least 64 in all).
SAMPLES_PER_CONTROL_POINT = 8
#: The XDATA application of a curve's role, name and weights.
APPID = "CURVE_VAE"
#: What AutoCAD refuses in a layer's name; each is written as `_`.
NOT_IN_LAYERS = '<>/\\":;?*|,=`'


def read_dxf(path: str | Path, name: str) -> list[np.ndarray]:
    """The curves of a DXF drawing's model space, in the order they are stored."""
    try:
        doc = ezdxf.readfile(str(path))
    except (OSError, ezdxf.DXFError) as err:
        raise CurveFileError(f"{name}: not a DXF drawing ({err})") from None
    found = (
        Found(f"{e.dxftype()} #{e.dxf.handle}" if e.dxf.handle else f"{e.dxftype()} of a block", _points(e), _role(e))
        for e in recursive_decompose(doc.modelspace())  # blocks' entities where they are inserted, transformed
        if e.dxftype() in KINDS
    )
    return drawn_curves(the_inputs(found, name), name, kinds="LWPOLYLINE, POLYLINE or SPLINE of 4 points")


def _role(e: Any) -> str | None:
    """An entity's role: its XDATA's, or its layer's first word."""
    if e.has_xdata(APPID):
        marks = dict(str(t.value).partition("=")[::2] for t in e.get_xdata(APPID) if t.code == 1000)
        if marks.get("role") in ROLES:
            return marks["role"]
    word = str(e.dxf.get("layer", "")).split("-", 1)[0]
    return word if word in ROLES else None


def layer_name(mark: Mapping[str, Any]) -> str:
    """`<role>-<name>`, with what AutoCAD refuses in a layer's name as `_`."""
    text = f"{mark['role']}-{mark.get('name', '')}"
    return "".join("_" if c in NOT_IN_LAYERS else c for c in text)


def xdata(mark: Mapping[str, Any]) -> list[tuple[int, str]]:
    """A curve's role, name, input (`of`) and weights, as XDATA strings."""
    tags = [(1000, f"role={mark['role']}"), (1000, f"name={mark.get('name', '')}")]
    if mark.get("of") is not None:
        tags.append((1000, f"of={mark['of']}"))
    if mark.get("weights"):
        tags.append((1000, f"weights={weights_text(mark['weights'])}"))
    return tags


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


def write_dxf(
    target: Path,
    *,
    splines: list[dict[str, Any] | None] | None,
    curves: list[np.ndarray] | None,
    marks: list[Mapping[str, Any]] | None = None,
) -> None:
    """A DXF (R2010) with a SPLINE per B-spline and an LWPOLYLINE per other curve (`splines[i]` None, or no splines:
    `curves[i]`); `marks`, one an entity, put each on its role's layer, in the page's colour, with its XDATA."""
    doc = ezdxf.new("R2010")
    msp = doc.modelspace()
    count = len(splines) if splines is not None else len(curves or [])
    entities: list[DXFGraphic] = []
    for i in range(count):
        s = splines[i] if splines is not None else None
        if s is not None:
            ctrl = [(float(x), float(y), 0.0) for x, y in s["control_points"]]
            entities.append(msp.add_open_spline(ctrl, degree=int(s["degree"]), knots=s["knots"]))
        else:
            entities.append(msp.add_lwpolyline([(float(x), float(y)) for x, y in (curves or [])[i]], format="xy"))
    if marks:
        doc.appids.new(APPID)
        for e, mark in zip(entities, marks):
            layer = layer_name(mark)
            if layer not in doc.layers:
                k = colour_index(dict(mark))
                aci = INTERPOLANT_ACI if mark.get("role") == "interpolant" else PALETTE_ACI[k] if k is not None else 7
                doc.layers.add(layer, color=aci)
            e.dxf.layer = layer
            e.set_xdata(APPID, xdata(mark))
    doc.saveas(target)
