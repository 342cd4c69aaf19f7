"""curve_vae.curvefiles' readers on real files: the page's own exports (downloaded from it in Chromium), airfoil
files laid out as the UIUC database's are (headers, remarks, notes, Fortran exponents), an Inkscape drawing and a DXF
written by ezdxf (tests/fixtures/files/README.md says what each one holds)."""

from __future__ import annotations

import importlib.util
import json
import re

import numpy as np
import pytest

from curve_vae.curvefiles import CurveFileError, CurveFileWarning, read_curve_files, read_curves
from tests.helpers import FIXTURES

FILES = FIXTURES / "files"


def _make_files():
    spec = importlib.util.spec_from_file_location("make_files", FILES / "make_files.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)  # type: ignore[union-attr]
    return module


MAKE = _make_files()
PAGE = json.loads((FILES / "page-export.json").read_text())["curves"]


def test_the_pages_json_export_gives_each_of_its_curves():
    curves = read_curves(FILES / "page-export.json")
    assert len(curves) == len(PAGE) == 4  # A, B, C and their mix
    for got, saved in zip(curves, PAGE):
        np.testing.assert_array_equal(got, saved["points"])


def test_the_pages_csv_export_gives_the_same_curves():
    curves = read_curves(FILES / "page-export.csv")
    assert [len(c) for c in curves] == [len(c["points"]) for c in PAGE]
    for got, saved in zip(curves, PAGE):
        np.testing.assert_array_equal(got, saved["points"])


def test_the_pages_svg_export_gives_its_strokes_y_up():
    """The board's paths, in its viewBox's units with y up: the drawn curves 700 below the API's (the board is 700
    high and its y points down), to the 3 decimals the page writes."""
    curves = read_curves(FILES / "page-export.svg")
    assert len(curves) == 3 + 3 + 1  # the strokes, their dashed reconstructions and the mix
    for got, saved in zip(curves[:3], PAGE[:3]):
        np.testing.assert_allclose(got, np.asarray(saved["points"]) - [0, 700], atol=1e-3)


def test_the_pages_dxf_export_gives_its_strokes_and_splines():
    curves = read_curves(FILES / "page-export.dxf")
    assert len(curves) == 3 + 3 + 1  # the strokes as polylines; the reconstructions and the mix as SPLINEs
    for got, saved in zip(curves[:3], PAGE[:3]):
        np.testing.assert_array_equal(got, saved["points"])
    mix = PAGE[3]["spline"]  # the export's mix: its spline sampled along its parameter
    np.testing.assert_allclose(curves[-1][[0, -1]], np.asarray(mix["control_points"])[[0, -1]], atol=1e-9)


@pytest.mark.parametrize(
    ("name", "code", "warning"),
    [
        pytest.param(
            "selig_notes.dat", "2412", r"selig_notes\.dat:72: the coordinates end here.*Profilbeiwerte", id="notes"
        ),
        pytest.param(
            "selig_two_line_header_notes.dat", "4412", r"notes\.dat:73: the coordinates end", id="header-and-notes"
        ),
        pytest.param("selig_remarks.dat", "0018", r"remarks\.dat:2: remarks after the numbers skipped on 2", id="->"),
        pytest.param("lednicer_two_line_header.dat", "2412", None, id="lednicer"),
        pytest.param("selig_fortran.dat", "6409", None, id="fortran-D"),
    ],
)
def test_airfoil_files_as_the_database_writes_them(name, code, warning, recwarn):
    (curve,) = read_curves(FILES / name)
    np.testing.assert_allclose(curve, MAKE.selig(code), atol=2e-6)  # Selig order, whatever the layout
    said = [str(w.message) for w in recwarn if issubclass(w.category, CurveFileWarning)]
    if warning:
        assert len(said) == 1 and re.search(warning, said[0]), said
    else:
        assert said == []


def test_a_folder_of_airfoils_with_notes_is_read_whole(tmp_path):
    for f in FILES.glob("*.dat"):
        (tmp_path / f.name).write_text(f.read_text())
    (tmp_path / "README.txt").write_text("where these came from")
    (tmp_path / ".ipynb_checkpoints").mkdir()
    (tmp_path / ".ipynb_checkpoints" / "half-saved.json").write_text("[[0, 0], [1,")  # hidden: not the user's curves
    with pytest.warns(CurveFileWarning, match=r"1 file\(s\) not of a curve kind skipped: README\.txt"):
        curves = read_curve_files(tmp_path)
    assert len(curves) == 5 and all(len(c) == 69 for c in curves)


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


def test_a_dxf_gives_its_polylines_and_spline_and_the_block_it_inserts():
    open_lw, closed_lw, old, spline, inserted = read_curves(FILES / "ezdxf_drawing.dxf")
    np.testing.assert_array_equal(open_lw, [[0, 0], [10, 4], [20, 5], [30, 3], [40, 0]])
    np.testing.assert_array_equal(closed_lw, [[50, 0], [60, 0], [60, 10], [50, 10], [50, 0]])
    np.testing.assert_array_equal(old, [[0, 20], [8, 26], [16, 28], [24, 26], [32, 20]])
    assert len(spline) == 64
    np.testing.assert_allclose(spline[[0, -1]], [[0, 40], [50, 45]], atol=1e-9)  # clamped: ends at its ends
    block = np.array([[0, 0], [5, 2], [10, 2.5], [15, 1.5], [20, 0]])
    np.testing.assert_allclose(inserted, [100, 10] + 2 * block @ [[0, 1], [-1, 0]], atol=1e-9)  # turned 90°, × 2


@pytest.mark.parametrize(
    ("name", "text", "curves"),
    [
        pytest.param("plain.csv", "0,0\n1,1\n2,0\n3,1\n\n0,0\n1,2\n2,2\n3,0\n", 2, id="blank-line-between"),
        pytest.param("header.csv", "x,y\n0,0\n1,1\n2,0\n3,1\n", 1, id="header"),
        pytest.param("cols.csv", "id,y,x\nA,0,0\nA,1,1\nA,0,2\nA,1,3\nB,0,0\nB,1,1\nB,2,2\nB,3,3\n", 2, id="named"),
        pytest.param("tabs.tsv", "x\ty\n0\t0\n1\t1\n2\t0\n3\t1\n", 1, id="tsv"),
        pytest.param("one.json", "[[0,0],[1,1],[2,0],[3,1]]", 1, id="one-curve"),
        pytest.param("body.json", '{"curves": [[[0,0],[1,1],[2,0],[3,1]]], "n_points": 9}', 1, id="api-body"),
        pytest.param("revolve.json", '{"curve": [[0,0],[1,1],[2,0],[3,1]], "segments": 8}', 1, id="revolve-body"),
    ],
)
def test_text_files_in_every_shape(tmp_path, name, text, curves):
    (tmp_path / name).write_text(text)
    got = read_curves(tmp_path / name)
    assert len(got) == curves and all(c.shape == (4, 2) for c in got)


def test_npz_arrays_by_name(tmp_path):
    np.savez(tmp_path / "c.npz", curves=np.zeros((3, 5, 2)), other=np.zeros(4))
    assert len(read_curves(tmp_path / "c.npz")) == 3
    np.savez(tmp_path / "prior.npz", weights=np.ones(2), means=np.zeros((2, 32)))
    with pytest.raises(CurveFileError, match=r"prior\.npz: no array of shape \(n, 2\)"):
        read_curves(tmp_path / "prior.npz")


@pytest.mark.parametrize(
    ("name", "text", "message"),
    [
        pytest.param("bad.csv", "x,y\n0,0\n1,oops\n", r"bad\.csv:3: expected two numbers x,y", id="csv-row"),
        pytest.param(
            "cols.csv",
            "curve,x,y\nA,0,0\nA,1,\n",
            r"cols\.csv:3: expected numbers in the columns named x and y",
            id="cols",
        ),
        pytest.param("three.csv", "0,0,1\n", r"three\.csv:1: expected two numbers x,y", id="csv-columns"),
        pytest.param("empty.json", "[]", r"empty\.json: no curve in this file", id="json-empty"),
        pytest.param("other.json", '{"latents": []}', r"other\.json: a JSON object needs a 'curves' list", id="obj"),
        pytest.param("nopts.json", '{"curves": [{"name": "A"}]}', r"curves\[0\] \(A\) is an object without 'points'"),
        pytest.param("broken.json", '{"curves": [', r"broken\.json:1: not JSON", id="json-syntax"),
        pytest.param("short.dat", "NACA\n1.0 0.0\n0.5 oops\n", r"short\.dat:3: expected two numbers x y", id="dat"),
        pytest.param("words.dat", "just a note\nno numbers\n", r"words\.dat: no coordinates", id="dat-empty"),
        pytest.param(
            "text.svg", '<svg xmlns="http://www.w3.org/2000/svg"><text>hi</text></svg>', r"text\.svg: no curve"
        ),
        pytest.param("lines.dxf", None, r"lines\.dxf: no curve in this drawing", id="dxf-empty"),
    ],
)
def test_a_file_without_curves_is_one_clear_error(tmp_path, name, text, message):
    if text is None:
        import ezdxf

        doc = ezdxf.new()
        doc.modelspace().add_line((0, 0), (1, 1))
        doc.saveas(tmp_path / name)
    else:
        (tmp_path / name).write_text(text)
    with pytest.raises(CurveFileError, match=message):
        read_curves(tmp_path / name)


def test_a_folder_names_the_file_it_cannot_read(tmp_path):
    (tmp_path / "a.json").write_text("[[0,0],[1,1],[2,0],[3,1]]")
    (tmp_path / "b.csv").write_text("0,0\n1,x\n")
    with pytest.raises(CurveFileError, match=r"b\.csv:2"):
        read_curve_files(tmp_path)
