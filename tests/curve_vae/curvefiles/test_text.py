"""curve_vae.curvefiles.text: curves from JSON (an API body, a list of curves, one curve, the page's export) and
CSV/TSV (x,y rows, a header naming the columns, the page's `curve,role,index,x,y`), on the page's own exports and on
files in every shape; a file without curves is one error naming the file and the line."""

from __future__ import annotations

import json

import numpy as np
import pytest

from curve_vae.curvefiles import CurveFileError, CurveFileWarning, parse_csv, parse_json, read_curves
from tests.helpers import FIXTURES

FILES = FIXTURES / "files"
PAGE = json.loads((FILES / "page-export.json").read_text())["curves"]
SQUARE_WAVE = [[0, 0], [1, 1], [2, 0], [3, 1]]


def test_the_pages_json_export_gives_its_drawn_curves_not_the_derived_ones():
    with pytest.warns(CurveFileWarning, match=r"page-export\.json: its 3 input curve\(s\) read; 14 derived curve"):
        curves = read_curves(FILES / "page-export.json")
    assert len(curves) == 3  # A, B and C; not their reconstructions, the mix or the in-betweens
    for got, saved in zip(curves, PAGE[:3]):
        assert saved["role"] == "input"
        np.testing.assert_array_equal(got, saved["points"])


def test_the_pages_csv_export_gives_the_same_curves():
    with pytest.warns(CurveFileWarning, match="14 derived"):
        curves = read_curves(FILES / "page-export.csv")
    assert [len(c) for c in curves] == [len(c["points"]) for c in PAGE[:3]]
    for got, saved in zip(curves, PAGE):
        np.testing.assert_array_equal(got, saved["points"])


def test_a_csv_of_derived_curves_only_gives_them_all():
    rows = [(n, i, x, y + k) for k, n in enumerate("AB") for i, (x, y) in enumerate(SQUARE_WAVE)]
    text = "curve,role,of,weights,index,x,y\n" + "".join(
        f"{n} reconstructed,reconstruction,{n},,{i},{x},{y}\n" for n, i, x, y in rows
    )
    a, b = parse_csv(text, "rec.csv")
    np.testing.assert_array_equal(b - a, np.ones((4, 2)) * [0, 1])


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
        pytest.param(
            "again.csv",
            "curve,x,y\nA,0,0\nA,1,1\nA,2,0\nA,3,1\nB,0,0\nB,1,1\nB,2,0\nB,3,1\nA,4,0\n",
            r"again\.csv:10: curve 'A' again after other curves \(its rows begin at row 2\): list each curve's rows",
            id="curve-again",
        ),
        pytest.param(
            "short.csv", "x,y,curve\n0,0,A\n1,1\n", r"short\.csv:3: no column 'curve' in '1,1'", id="no-name-cell"
        ),
        pytest.param("empty.json", "[]", r"empty\.json: no curve in this file", id="json-empty"),
        pytest.param("other.json", '{"latents": []}', r"other\.json: a JSON object needs a 'curves' list", id="obj"),
        pytest.param("nopts.json", '{"curves": [{"name": "A"}]}', r"curves\[0\] \(A\) is an object without 'points'"),
        pytest.param("broken.json", '{"curves": [', r"broken\.json:1: not JSON", id="json-syntax"),
    ],
)
def test_a_file_without_curves_is_one_clear_error(tmp_path, name, text, message):
    (tmp_path / name).write_text(text)
    with pytest.raises(CurveFileError, match=message):
        read_curves(tmp_path / name)


@pytest.mark.parametrize(
    "text",
    [
        pytest.param("x;y\n0;0\n1;1\n2;0\n3;1\n", id="semicolons"),
        pytest.param("0 0\n1   1\n2 0\n3 1\n", id="spaces"),
        pytest.param("Y,X\n0,0\n1,1\n0,2\n1,3\n", id="named-columns-swapped"),
        pytest.param("\n\nx,y\n0,0\n1,1\n2,0\n3,1\n\n\n", id="blank-lines-around"),
        pytest.param("u,v\n0,0\n1,1\n2,0\n3,1\n", id="two-unnamed-columns"),
    ],
)
def test_csv_rows_in_any_layout_give_the_points(text):
    (curve,) = parse_csv(text, "c.csv")
    np.testing.assert_array_equal(curve, SQUARE_WAVE)
    assert curve.dtype == np.float64


def test_where_a_column_names_the_curves_blank_lines_change_nothing():
    text = "curve,x,y\nA,0,0\nA,1,1\n\nA,2,0\nA,3,1\n\n\nB,5,5\nB,6,6\nB,7,5\nB,8,6\n"
    a, b = parse_csv(text, "gaps.csv")
    np.testing.assert_array_equal(a, SQUARE_WAVE)
    np.testing.assert_array_equal(b, np.asarray(SQUARE_WAVE) + 5)


def test_a_curve_column_starts_a_curve_where_its_value_changes():
    text = "curve,role,index,x,y\nA,input,0,0,0\nA,input,1,1,1\nA,input,2,2,0\nA,input,3,3,1\n"
    text += "B,input,0,5,5\nB,input,1,6,6\nB,input,2,7,5\nB,input,3,8,6\n"
    a, b = parse_csv(text, "page.csv")
    np.testing.assert_array_equal(a, SQUARE_WAVE)
    np.testing.assert_array_equal(b, np.asarray(SQUARE_WAVE) + 5)


@pytest.mark.parametrize(
    ("text", "message"),
    [
        pytest.param("", r"e\.csv: no curve in this file \(it is empty\)", id="empty"),
        pytest.param("a,b,c\n1,2,3\n", r"e\.csv:1: a header row needs columns named x and y, got a,b,c", id="header"),
        pytest.param("0,0\n1,1\n2,0\n", r"e\.csv: curve 0 has 3 points; a curve needs at least 4", id="3-points"),
    ],
)
def test_csv_without_a_curve_says_why(text, message):
    with pytest.raises(CurveFileError, match=message):
        parse_csv(text, "e.csv")


@pytest.mark.parametrize(
    "doc",
    [
        pytest.param(SQUARE_WAVE, id="one-curve"),
        pytest.param([SQUARE_WAVE], id="list"),
        pytest.param({"curves": [SQUARE_WAVE]}, id="api-body"),
        pytest.param({"name": "A", "points": SQUARE_WAVE}, id="page-curve"),
        pytest.param({"curves": [{"name": "A", "points": SQUARE_WAVE}]}, id="page-export"),
        pytest.param({"curve": SQUARE_WAVE, "segments": 8}, id="revolve-body"),
    ],
)
def test_json_in_every_shape_gives_the_curve(doc):
    (curve,) = parse_json(json.dumps(doc), "c.json")
    np.testing.assert_array_equal(curve, SQUARE_WAVE)


@pytest.mark.parametrize("doc", ["3", '"curves"', "null"], ids=["number", "string", "null"])
def test_json_that_is_neither_list_nor_object_names_the_shapes_read(doc):
    with pytest.raises(CurveFileError, match=r"c\.json: JSON of curves is a list or an object; the shapes read are"):
        parse_json(doc, "c.json")
