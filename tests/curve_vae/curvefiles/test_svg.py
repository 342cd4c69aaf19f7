"""curve_vae.curvefiles.svg: every path, polyline and polygon of a drawing with its transforms, y up (the page's own
export, an Inkscape drawing); B-splines written as exact cubic Béziers, read back by svgelements, which did not write
them; what is not a curve skipped with a warning, a drawing with none an error."""

from __future__ import annotations

import json

import numpy as np
import pytest
import svgelements as se

from curve_vae.curvefiles import CurveFileError, CurveFileWarning, read_curves, spline_beziers, write_output
from tests.helpers import FIXTURES

FILES = FIXTURES / "files"
PAGE = json.loads((FILES / "page-export.json").read_text())["curves"]


def _spline(seed: int, n: int = 31, *, repeated: bool = False) -> dict:
    rng = np.random.default_rng(seed)
    inner = np.sort(rng.uniform(0, 1, n - 4))
    if repeated:
        inner[5] = inner[6]  # a double knot: the spline is only C1 there
    knots = np.r_[[0.0] * 4, inner, [1.0] * 4]
    return {"control_points": rng.normal(size=(n, 2)).tolist(), "knots": knots.tolist(), "degree": 3}


def _user(undo: se.Matrix, p: se.Point) -> tuple[float, float]:
    """A point of the parsed drawing in its viewBox's units, y up."""
    q = undo.point_in_matrix_space(p)
    return q.x, -q.y


def test_the_pages_svg_export_gives_its_strokes_where_they_were_drawn():
    """The page writes SVG as the command line does: a point (x, y) at (x, -y) in user units, 10 digits; its drawn
    curves (class input) come back in API coordinates."""
    with pytest.warns(CurveFileWarning, match="its 3 input curve"):
        curves = read_curves(FILES / "page-export.svg")
    assert len(curves) == 3
    for got, saved in zip(curves, PAGE[:3]):
        np.testing.assert_allclose(got, saved["points"], rtol=1e-9)
    svg = se.SVG.parse(str(FILES / "page-export.svg"))
    assert max(svg.width, svg.height) == 800  # px, as the command line draws


def test_the_pages_sheet_of_in_betweens_gives_each_at_one_scale():
    """The sheet holds interpolants only: every one is read, each its curve moved into its cell and scaled alike."""
    sweep = [c for c in PAGE if c["role"] == "interpolant" and c["name"] != "mix"]
    curves = read_curves(FILES / "page-sheet.svg")
    assert len(curves) == len(sweep) > 1
    scales = []
    for got, saved in zip(curves, sweep):
        want = np.asarray(saved["points"])
        (g, w) = (got - got.mean(axis=0), want - want.mean(axis=0))
        scales.append(np.linalg.norm(g) / np.linalg.norm(w))
        np.testing.assert_allclose(g, w * scales[-1], atol=1e-6 * np.abs(g).max())
    np.testing.assert_allclose(scales, scales[0], rtol=1e-6)


def test_an_inkscape_drawing_gives_its_path_polyline_and_polygon_with_their_transforms():
    cubic, polyline, polygon = read_curves(FILES / "inkscape_drawing.svg")
    # the layer's translate(-12.5,-30.25) on the path's absolute start and its segments' ends (y up)
    ends = np.array([[40.5, 120.25], [110.8, 107.85], [170.9, 99.55]]) + [-12.5, -30.25]
    np.testing.assert_allclose(cubic[::16], ends * [1, -1], atol=1e-9)
    assert len(cubic) == 33  # two curved segments, 16 points each after the start
    pts = np.array([[30, 150], [45, 130], [60, 140], [75, 120], [90, 135], [105, 115]]) * 1.2
    a = np.radians(15)
    rot = np.array([[np.cos(a), -np.sin(a)], [np.sin(a), np.cos(a)]])
    placed = (pts - [100, 150]) @ rot.T + [100, 150] + [-12.5, -30.25]  # rotate(15,100,150) scale(1.2), the layer
    np.testing.assert_allclose(polyline, placed * [1, -1], atol=1e-9)
    assert len(polygon) == 5 and np.array_equal(polygon[0], polygon[-1])  # a polygon is a loop


def test_svg_of_splines_is_one_path_of_exact_cubics_per_curve(tmp_path):
    splines = [_spline(2), _spline(3, n=12)]
    out = tmp_path / "out.svg"
    write_output(str(out), {"splines": splines, "mse": [0.1, 0.2]})
    svg = se.SVG.parse(str(out))
    undo = ~se.Matrix(svg.viewbox_transform)
    paths = [e for e in svg.elements() if isinstance(e, se.Path)]
    assert len(paths) == 2
    for path, s in zip(paths, splines):
        cubics = [seg for seg in path.segments() if isinstance(seg, se.CubicBezier)]
        got = np.array([[_user(undo, p) for p in (c.start, c.control1, c.control2, c.end)] for c in cubics])
        np.testing.assert_allclose(got, spline_beziers(s["control_points"], s["knots"]), atol=1e-8)
    assert [len(c) for c in read_curves(out)] == [1 + 16 * 28, 1 + 16 * 9]  # n - 3 spans of 16 points


def _drawing(tmp_path, body: str, name: str = "d.svg"):
    (tmp_path / name).write_text(f'<svg xmlns="http://www.w3.org/2000/svg">{body}</svg>')
    return tmp_path / name


def test_a_file_without_curves_is_one_clear_error(tmp_path):
    with pytest.raises(CurveFileError, match=r"text\.svg: no curve"):
        read_curves(_drawing(tmp_path, "<text>hi</text>", "text.svg"))


def test_broken_xml_is_not_a_drawing(tmp_path):
    (tmp_path / "b.svg").write_text('<svg xmlns="http://www.w3.org/2000/svg"><path d="M0,0 L1,1"')
    with pytest.raises(CurveFileError, match=r"b\.svg: not an SVG drawing"):
        read_curves(tmp_path / "b.svg")


def test_each_subpath_is_a_curve_y_up_and_a_closed_one_ends_at_its_start(tmp_path):
    path = _drawing(tmp_path, '<path d="M0,0 L1,1 L2,0 L3,1 M10,10 L12,10 L12,12 L10,12 Z"/>')
    open_, closed = read_curves(path)
    np.testing.assert_array_equal(open_, [[0, 0], [1, -1], [2, 0], [3, -1]])
    np.testing.assert_array_equal(closed, [[10, -10], [12, -10], [12, -12], [10, -12], [10, -10]])


def test_a_curved_segment_is_sampled_on_its_curve(tmp_path):
    """A quarter circle of radius 5 about (0, 0), drawn as an arc: 16 points past its start, each 5 from the centre."""
    (curve,) = read_curves(_drawing(tmp_path, '<path d="M5,0 A5,5 0 0,1 0,5"/>'))
    assert len(curve) == 1 + 16
    np.testing.assert_allclose(np.hypot(*curve.T), 5.0, atol=1e-9)
    np.testing.assert_allclose(curve[[0, -1]], [[5, 0], [0, -5]], atol=1e-9)


def test_a_path_of_fewer_than_4_points_is_skipped_naming_it(tmp_path):
    path = _drawing(tmp_path, '<path id="tick" d="M0,0 L1,1 L2,0"/><polyline points="0,0 1,1 2,0 3,1"/>')
    with pytest.warns(CurveFileWarning, match=r"d\.svg: path#tick: 3 points, not a curve; skipped"):
        (curve,) = read_curves(path)
    np.testing.assert_array_equal(curve, [[0, 0], [1, -1], [2, 0], [3, -1]])


def test_an_airfoils_svg_is_drawn_at_a_size_people_see_and_read_back_at_its_own(tmp_path):
    """An airfoil of chord 1 is written 800 px wide (width and height in px, the curve's own coordinates in the
    viewBox, a stroke of 1.5 screen pixels at any scale) and read back at chord 1; the file says its y convention."""
    t = np.linspace(0, 2 * np.pi, 81)
    airfoil = np.c_[0.5 + 0.5 * np.cos(t), 0.06 * np.sin(t)]
    out = tmp_path / "airfoil.svg"
    write_output(str(out), {"curves": [airfoil.tolist()], "mse": [0.0]})
    svg = se.SVG.parse(str(out))
    assert (svg.width, round(svg.height)) == (800, round(800 * (0.12 + 0.1) / 1.1))
    text = out.read_text()
    assert 'vector-effect="non-scaling-stroke"' in text and 'stroke-width="1.5"' in text
    assert "(x, -y)" in text  # the y convention, stated
    np.testing.assert_allclose(read_curves(out)[0], airfoil, atol=1e-9)
