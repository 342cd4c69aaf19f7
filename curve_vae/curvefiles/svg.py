"""SVG in and out. In: every path, polyline and polygon of a drawing, its transforms applied (svgelements), each
subpath a curve; lines keep their vertices, curved segments are sampled; a path's class `input`, `reconstruction` or
`interpolant` is its role (roles.py). Out: a path per curve, a B-spline as its exact cubic Bézier segments; given
marks, each path's class is its role and `data-name`, `data-of` and `data-weights` say the rest, drawn as the page
draws them. SVG's y points down and curves' y up: a point (x, y) of a curve is (x, −y) in the drawing's user units
(its viewBox), both ways."""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path as FilePath
from typing import Any
from xml.sax.saxutils import quoteattr

import numpy as np
import svgelements as se

from curve_vae.curvefiles.common import CurveFileError, drawn_curves
from curve_vae.curvefiles.roles import INTERPOLANT_COLOUR, PALETTE, Found, colour_index, role_of, the_inputs

#: The longer side of a written drawing, in CSS pixels: its curves keep their own coordinates in the viewBox, and a
#: browser shows an airfoil of chord 1 at this width, not at one pixel.
DISPLAY_PX = 800
#: Stroke width on screen, in CSS pixels, whatever the drawing's scale (vector-effect: non-scaling-stroke).
STROKE_PX = 1.5

#: Points per curved segment (cubic, quadratic, arc) of a drawing's path.
SAMPLES_PER_SEGMENT = 16
#: The interpolants' colour and that of a curve without a role or name; the others': roles.PALETTE by their names.
INTERPOLANT, UNMARKED = INTERPOLANT_COLOUR, PALETTE[0]
#: How a role is drawn: inputs as pale bands under the rest, reconstructions dashed, interpolants solid.
STYLES = {
    "input": 'stroke-width="6" stroke-opacity="0.3" stroke-linecap="round" stroke-linejoin="round"',
    "reconstruction": 'stroke-dasharray="6 4"',
    "interpolant": "",
}
DESC = (
    "curve-vae: each path is a curve in its own coordinates, y up: its point (x, y) is drawn at (x, -y), SVG's y "
    "pointing down. A path's class is its role (input, reconstruction, interpolant); data-name names it, data-of "
    "names a reconstruction's input, data-weights an interpolant's weights by input."
)


def read_svg(path: str | FilePath, name: str) -> list[np.ndarray]:
    """The curves of an SVG drawing, in document order."""
    try:
        svg = se.SVG.parse(str(path), reify=True)
    except Exception as e:  # svgelements raises ElementTree's ParseError and others for broken XML
        raise CurveFileError(f"{name}: not an SVG drawing ({e})") from None
    undo = ~se.Matrix(svg.viewbox_transform) if isinstance(svg, se.SVG) and svg.viewbox_transform else se.Matrix()
    found = (
        Found(_label(element), _apply(undo, pts) * [1, -1], role_of(element.values.get("attributes", {}).get("class")))
        for element in (svg.elements() if isinstance(svg, se.SVG) else [])
        if isinstance(element, se.Path | se.Polyline | se.Polygon)
        for pts in _subpaths(se.Path(element) if not isinstance(element, se.Path) else element)
    )
    return drawn_curves(the_inputs(found, name), name, kinds="path, polyline or polygon of 4 points or more")


def _label(element: se.Shape) -> str:
    tag = element.values.get("tag", "path")
    return f"{tag}#{element.id}" if element.id else tag


def _apply(m: se.Matrix, pts: np.ndarray) -> np.ndarray:
    return pts @ np.array([[m.a, m.b], [m.c, m.d]]) + [m.e, m.f]


def _subpaths(path: se.Path) -> list[np.ndarray]:
    """Each subpath's points: the vertices of lines, samples of curved segments, a closed one ending at its start."""
    out: list[list[np.ndarray]] = []
    s = np.linspace(0, 1, SAMPLES_PER_SEGMENT + 1)[1:]
    for seg in path.segments():
        if isinstance(seg, se.Move):
            out.append([np.array([[seg.end.x, seg.end.y]])])
        elif not out:
            continue
        elif isinstance(seg, se.Line | se.Close):
            out[-1].append(np.array([[seg.end.x, seg.end.y]]))
        elif seg.end is not None:
            out[-1].append(np.asarray(seg.npoint(s), dtype=np.float64).reshape(-1, 2))
    curves = []
    for parts in out:
        pts = np.concatenate(parts)
        keep = np.r_[True, np.any(np.diff(pts, axis=0) != 0, axis=1)]  # a Close onto the last point adds nothing
        curves.append(pts[keep])
    return curves


def _fmt(v: float) -> str:
    return f"{v:.10g}"


def _d_points(pts: np.ndarray) -> str:
    return "M" + " L".join(f"{_fmt(x)},{_fmt(-y)}" for x, y in pts)


def _d_beziers(segments: np.ndarray) -> str:
    d = [f"M{_fmt(segments[0, 0, 0])},{_fmt(-segments[0, 0, 1])}"]
    for seg in segments:
        d.append("C" + " ".join(f"{_fmt(x)},{_fmt(-y)}" for x, y in seg[1:]))
    return " ".join(d)


def weights_text(weights: Mapping[str, float]) -> str:
    """An interpolant's weights as files write them: `A=0.75 B=0.25`."""
    return " ".join(f"{k}={float(v)!r}" for k, v in weights.items())


def _marked(mark: Mapping[str, Any] | None) -> str:
    """A path's role, names, weights and stroke, as attributes."""
    if not mark or mark.get("role") not in STYLES:
        return f'stroke="{UNMARKED}"'
    role = mark["role"]
    attrs = [f'class="{role}"', f"data-name={quoteattr(str(mark.get('name', '')))}"]
    if mark.get("of") is not None:
        attrs.append(f"data-of={quoteattr(str(mark['of']))}")
    if mark.get("weights"):
        attrs.append(f"data-weights={quoteattr(weights_text(mark['weights']))}")
    k = colour_index(dict(mark))
    colour = INTERPOLANT if role == "interpolant" else PALETTE[k] if k is not None else UNMARKED
    return " ".join([*attrs, f'stroke="{colour}"', STYLES[role]]).strip()


def svg_text(
    paths: list[np.ndarray], *, beziers: bool | list[bool], marks: list[Mapping[str, Any]] | None = None
) -> str:
    """An SVG document with one path per item: points (n, 2), or with `beziers` (for all, or one flag an item) cubic
    segments (m, 4, 2); `marks`, one a path, give each its role, `name`, `of` (a reconstruction's input) and
    `weights` (an interpolant's)."""
    allpts = np.concatenate([p.reshape(-1, 2) for p in paths])
    lo, hi = allpts.min(axis=0), allpts.max(axis=0)
    size = float(max(hi[0] - lo[0], hi[1] - lo[1], 1e-9))
    pad = 0.05 * size
    x0, y0, w, h = lo[0] - pad, -hi[1] - pad, hi[0] - lo[0] + 2 * pad, hi[1] - lo[1] + 2 * pad
    px = DISPLAY_PX / max(w, h)
    lines = [
        '<?xml version="1.0" encoding="UTF-8"?>',
        f'<svg xmlns="http://www.w3.org/2000/svg" width="{w * px:.0f}px" height="{max(h * px, 1):.0f}px" '
        f'viewBox="{_fmt(x0)} {_fmt(y0)} {_fmt(w)} {_fmt(h)}">',
        f"<desc>{DESC}</desc>",
        f'<g fill="none" stroke-width="{STROKE_PX}">',
    ]
    flags = beziers if isinstance(beziers, list) else [beziers] * len(paths)
    for i, (p, bezier) in enumerate(zip(paths, flags)):
        d = _d_beziers(p) if bezier else _d_points(p)
        mark = _marked(marks[i] if marks else None)
        lines.append(f'<path id="curve-{i}" {mark} vector-effect="non-scaling-stroke" d="{d}"/>')
    lines += ["</g>", "</svg>", ""]
    return "\n".join(lines)
