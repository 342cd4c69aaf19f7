"""curve_vae.curvefiles.dxf: a drawing's LWPOLYLINEs, POLYLINEs and SPLINEs, those of inserted blocks where the
INSERT puts them (the page's own export, a drawing ezdxf wrote); B-splines written as SPLINE entities with their
control points and knots exactly; a drawing without curves, or a file that is not one, an error naming it."""

from __future__ import annotations

import json

import ezdxf
import numpy as np
import pytest
from scipy.interpolate import BSpline

from curve_vae.curvefiles import CurveFileError, CurveFileWarning, read_curves, write_output
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


def test_the_pages_dxf_export_gives_its_strokes_and_holds_its_splines_exactly():
    """The drawn curves as LWPOLYLINEs (read back as they were), the reconstructions and the mix as SPLINEs with their
    control points and knots exactly, the in-betweens as LWPOLYLINEs: each entity one curve of the drawing."""
    with pytest.warns(CurveFileWarning, match="its 3 input curve"):
        curves = read_curves(FILES / "page-export.dxf")
    assert len(curves) == 3
    for got, saved in zip(curves, PAGE[:3]):
        np.testing.assert_array_equal(got, saved["points"])
    entities = list(ezdxf.readfile(FILES / "page-export.dxf").modelspace())
    assert len(entities) == len(PAGE)
    for e, saved in zip(entities, PAGE):
        if "spline" in saved:
            assert e.dxftype() == "SPLINE"
            np.testing.assert_array_equal(np.asarray(e.control_points)[:, :2], saved["spline"]["control_points"])
            np.testing.assert_array_equal(list(e.knots), saved["spline"]["knots"])
        else:
            assert e.dxftype() == "LWPOLYLINE"
            np.testing.assert_array_equal(list(e.get_points("xy")), saved["points"])


def test_a_dxf_gives_its_polylines_and_spline_and_the_block_it_inserts():
    open_lw, closed_lw, old, spline, inserted = read_curves(FILES / "ezdxf_drawing.dxf")
    np.testing.assert_array_equal(open_lw, [[0, 0], [10, 4], [20, 5], [30, 3], [40, 0]])
    np.testing.assert_array_equal(closed_lw, [[50, 0], [60, 0], [60, 10], [50, 10], [50, 0]])
    np.testing.assert_array_equal(old, [[0, 20], [8, 26], [16, 28], [24, 26], [32, 20]])
    assert len(spline) == 64
    np.testing.assert_allclose(spline[[0, -1]], [[0, 40], [50, 45]], atol=1e-9)  # clamped: ends at its ends
    block = np.array([[0, 0], [5, 2], [10, 2.5], [15, 1.5], [20, 0]])
    np.testing.assert_allclose(inserted, [100, 10] + 2 * block @ [[0, 1], [-1, 0]], atol=1e-9)  # turned 90°, × 2


def test_dxf_of_splines_holds_their_control_points_and_knots(tmp_path):
    splines = [_spline(4), _spline(5, n=8)]
    out = tmp_path / "out.dxf"
    write_output(str(out), {"splines": splines})
    entities = list(ezdxf.readfile(out).modelspace().query("SPLINE"))
    assert len(entities) == 2
    for e, s in zip(entities, splines):
        assert e.dxf.degree == 3
        np.testing.assert_allclose(np.asarray(e.control_points)[:, :2], s["control_points"], atol=1e-12)
        np.testing.assert_allclose(e.knots, s["knots"], atol=1e-12)
    curves = read_curves(out)
    exact = BSpline(np.asarray(splines[0]["knots"]), np.asarray(splines[0]["control_points"]), 3)
    np.testing.assert_allclose(curves[0][[0, -1]], exact([0.0, 1.0]), atol=1e-9)


def test_a_file_without_curves_is_one_clear_error(tmp_path):
    doc = ezdxf.new()
    doc.modelspace().add_line((0, 0), (1, 1))
    doc.saveas(tmp_path / "lines.dxf")
    with pytest.raises(CurveFileError, match=r"lines\.dxf: no curve in this drawing"):
        read_curves(tmp_path / "lines.dxf")


def test_a_file_that_is_not_dxf_is_named(tmp_path):
    (tmp_path / "notes.dxf").write_text("not a drawing at all\n")
    with pytest.raises(CurveFileError, match=r"notes\.dxf: not a DXF drawing"):
        read_curves(tmp_path / "notes.dxf")


def test_a_bulge_is_read_as_its_arc(tmp_path):
    """(0, 0) to (2, 0) with bulge 1: the half circle about (1, 0) of radius 1, counter-clockwise, through (1, -1);
    then a straight edge to (2, 3). ezdxf draws an arc as cubic Béziers, a quarter circle's off it by at most
    2.7e-4 of the radius, and the reader flattens them to 1e-4 of the drawing's size."""
    doc = ezdxf.new()
    doc.modelspace().add_lwpolyline([(0, 0, 1.0), (2, 0, 0.0), (2, 3, 0.0)], format="xyb")
    doc.saveas(tmp_path / "arc.dxf")
    (curve,) = read_curves(tmp_path / "arc.dxf")
    arc = curve[:-1]
    assert len(arc) > 8
    np.testing.assert_allclose(np.hypot(arc[:, 0] - 1, arc[:, 1]), 1.0, atol=2.8e-4 + 3e-4)
    np.testing.assert_allclose([arc[0], arc[-1], curve[-1]], [[0, 0], [2, 0], [2, 3]], atol=1e-12)
    assert arc[:, 1].min() == pytest.approx(-1.0, abs=1e-3) and arc[:, 1].max() <= 1e-12
