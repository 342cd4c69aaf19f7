"""SVG in and out. In: every path, polyline and polygon of a drawing, its transforms applied (svgelements), each
subpath a curve; lines keep their vertices, curved segments are sampled. Out: a path per curve, a B-spline as its
exact cubic Bézier segments. SVG's y points down and curves' y up: a point (x, y) of a curve is (x, −y) in the
drawing's user units (its viewBox), both ways."""

from __future__ import annotations

from pathlib import Path as FilePath

import numpy as np
import svgelements as se

from curve_vae.curvefiles.common import CurveFileError, drawn_curves

#: The longer side of a written drawing, in CSS pixels: its curves keep their own coordinates in the viewBox, and a
#: browser shows an airfoil of chord 1 at this width, not at one pixel.
DISPLAY_PX = 800
#: Stroke width on screen, in CSS pixels, whatever the drawing's scale (vector-effect: non-scaling-stroke).
STROKE_PX = 1.5

#: Points per curved segment (cubic, quadratic, arc) of a drawing's path.
SAMPLES_PER_SEGMENT = 16


def read_svg(path: str | FilePath, name: str) -> list[np.ndarray]:
    """The curves of an SVG drawing, in document order."""
    try:
        svg = se.SVG.parse(str(path), reify=True)
    except Exception as e:  # svgelements raises ElementTree's ParseError and others for broken XML
        raise CurveFileError(f"{name}: not an SVG drawing ({e})") from None
    undo = ~se.Matrix(svg.viewbox_transform) if isinstance(svg, se.SVG) and svg.viewbox_transform else se.Matrix()
    found = (
        (_label(element), _apply(undo, pts) * [1, -1])
        for element in (svg.elements() if isinstance(svg, se.SVG) else [])
        if isinstance(element, se.Path | se.Polyline | se.Polygon)
        for pts in _subpaths(se.Path(element) if not isinstance(element, se.Path) else element)
    )
    return drawn_curves(found, name, kinds="path, polyline or polygon of 4 points or more")


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


def svg_text(paths: list[np.ndarray], *, beziers: bool) -> str:
    """An SVG document with one path per item: points (n, 2), or with `beziers` cubic segments (m, 4, 2)."""
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
        "<desc>curve-vae: each path is a curve in its own coordinates, y up: its point (x, y) is drawn at (x, -y), "
        "SVG's y pointing down.</desc>",
        f'<g fill="none" stroke="#1f77b4" stroke-width="{STROKE_PX}">',
    ]
    for i, p in enumerate(paths):
        d = _d_beziers(p) if beziers else _d_points(p)
        lines.append(f'<path id="curve-{i}" vector-effect="non-scaling-stroke" d="{d}"/>')
    lines += ["</g>", "</svg>", ""]
    return "\n".join(lines)
