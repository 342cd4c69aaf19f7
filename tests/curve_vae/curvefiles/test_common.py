"""curve_vae.curvefiles.common: numbers as coordinate files write them, the check that makes arrays curves (each
refusal naming the file, the curve and the point), and a drawing's entities too short to be curves skipped by name."""

from __future__ import annotations

import numpy as np
import pytest

from curve_vae.curvefiles.common import MIN_POINTS, CurveFileError, CurveFileWarning, as_curves, drawn_curves, number

SQUARE_WAVE = [[0, 0], [1, 1], [2, 0], [3, 1]]


@pytest.mark.parametrize(
    ("token", "value"),
    [
        ("0.997912D+00", 0.997912),
        ("1.0d-02", 0.01),
        ("-.5", -0.5),
        ("+3", 3.0),
        ("7.", 7.0),
        ("1E3", 1000.0),
        ("  2.5\t", 2.5),
    ],
)
def test_a_number_as_coordinate_files_write_it(token, value):
    assert number(token) == value


@pytest.mark.parametrize("token", ["", "x", "1.2.3", "nan", "inf", "0x10", "1,5", "1e", "--1"])
def test_what_is_not_a_coordinate_is_none(token):
    assert number(token) is None


def test_curves_are_float64_arrays_of_the_points_given():
    a, b = as_curves([SQUARE_WAVE, np.array(SQUARE_WAVE, np.int32) * 2], "f")
    assert a.dtype == b.dtype == np.float64
    np.testing.assert_array_equal(b, np.array(SQUARE_WAVE) * 2)


@pytest.mark.parametrize(
    ("data", "message"),
    [
        pytest.param([SQUARE_WAVE, [[0, 0], [1]]], "f: curve 1 must be a list of [x, y] pairs of numbers", id="ragged"),
        pytest.param([[["a", "b"]] * 4], "f: curve 0 must be a list of [x, y] pairs of numbers", id="words"),
        pytest.param([[[0, 0, 0]] * 4], "f: curve 0 must be a list of [x, y] pairs, got shape (4, 3)", id="xyz"),
        pytest.param([[0, 1, 2, 3]], "f: curve 0 must be a list of [x, y] pairs, got shape (4,)", id="flat"),
        pytest.param([SQUARE_WAVE, [*SQUARE_WAVE[:2], [2, float("inf")], [3, 1]]], "f: curve 1 point 2 is not finite",
                     id="inf"),
        pytest.param([SQUARE_WAVE[:3]], f"f: curve 0 has 3 points; a curve needs at least {MIN_POINTS}", id="3-points"),
        pytest.param([], "f: no curve in this file", id="none"),
    ],
)  # fmt: skip
def test_what_is_not_a_curve_is_named(data, message):
    with pytest.raises(CurveFileError) as e:
        as_curves(data, "f")
    assert str(e.value) == message


def test_a_drawings_entity_of_3_points_is_skipped_by_its_label():
    found = [("LINE-ish #A1", np.array(SQUARE_WAVE[:3], float)), ("LWPOLYLINE #B2", np.array(SQUARE_WAVE, float))]
    with pytest.warns(CurveFileWarning) as said:
        (curve,) = drawn_curves(found, "d.dxf", kinds="polylines")
    assert [str(w.message) for w in said] == ["d.dxf: LINE-ish #A1: 3 points, not a curve; skipped"]
    np.testing.assert_array_equal(curve, SQUARE_WAVE)


def test_a_drawing_with_no_curve_left_says_which_kinds_count():
    with pytest.warns(CurveFileWarning), pytest.raises(CurveFileError) as e:
        drawn_curves([("path#p", np.zeros((2, 2)))], "d.svg", kinds="path or polygon of 4 points")
    assert str(e.value) == "d.svg: no curve in this drawing (no path or polygon of 4 points)"
