"""curve_vae.curvefiles.dat: airfoil coordinate files as the UIUC database writes them (Selig and Lednicer, headers
of any length, remarks after the numbers, notes after the coordinates, Fortran exponents), each read into Selig order;
what is skipped is a warning naming the line, what cuts the coordinates short an error naming it."""

from __future__ import annotations

import importlib.util
import re

import numpy as np
import pytest

from curve_vae.cli import main
from curve_vae.curvefiles import CurveFileError, CurveFileWarning, parse_dat, read_curves
from tests.helpers import FIXTURES

FILES = FIXTURES / "files"


def _make_files():
    spec = importlib.util.spec_from_file_location("make_files", FILES / "make_files.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)  # type: ignore[union-attr]
    return module


MAKE = _make_files()


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


def test_airfoil_dat_files_selig_and_lednicer(tmp_path, capsys):
    selig = tmp_path / "selig.dat"
    selig.write_text("NACA 0012\n1.0 0.0\n0.5 0.05\n0.0 0.0\n0.5 -0.05\n1.0 0.0\n")
    lednicer = tmp_path / "lednicer.dat"
    lednicer.write_text("NACA 0012\n3. 3.\n\n0.0 0.0\n0.5 0.05\n1.0 0.0\n\n0.0 0.0\n0.5 -0.05\n1.0 0.0\n")
    (curve,) = read_curves(str(selig))
    (same,) = read_curves(str(lednicer))
    np.testing.assert_array_equal(curve, same)  # Lednicer's two surfaces come back in Selig order
    assert curve.shape == (5, 2)
    bad = tmp_path / "bad.dat"
    bad.write_text("NACA 0012\n1.0 0.0\n0.5 oops\n")
    with pytest.raises(ValueError, match=r"bad\.dat:3: expected two numbers x y"):
        read_curves(str(bad))
    assert main(["fit", str(bad)]) == 2
    assert "bad.dat:3" in capsys.readouterr().err


@pytest.mark.parametrize(
    ("name", "text", "message"),
    [
        pytest.param("short.dat", "NACA\n1.0 0.0\n0.5 oops\n", r"short\.dat:3: expected two numbers x y", id="dat"),
        pytest.param("words.dat", "just a note\nno numbers\n", r"words\.dat: no coordinates", id="dat-empty"),
    ],
)
def test_a_file_without_curves_is_one_clear_error(tmp_path, name, text, message):
    (tmp_path / name).write_text(text)
    with pytest.raises(CurveFileError, match=message):
        read_curves(tmp_path / name)


SELIG = [[1.0, 0.0], [0.5, 0.05], [0.0, 0.0], [0.5, -0.05], [1.0, 0.0]]


@pytest.mark.parametrize(
    "text",
    [
        pytest.param("T\n1.0 0.0\n0.5 0.05\n0.0 0.0\n0.5 -0.05\n1.0 0.0\n", id="selig"),
        pytest.param("T\n1.0,0.0\n0.5,0.05\n0.0,0.0\n0.5,-0.05\n1.0,0.0\n", id="commas"),
        pytest.param("T\n1.000000 0.000000\n0.500000 0.050000\n0.000000 0.000000\n0.500000-0.050000\n"
                     "1.000000 0.000000\n", id="fortran-columns-abutting"),
        pytest.param("T\n1.0D+00 0.0D+00\n5.0D-01 5.0D-02\n0.0 0.0\n5.0d-01 -5.0d-02\n1.0 0.0\n", id="fortran-D"),
        pytest.param("T\n2. 3.\n0.0 0.0\n1.0 0.0\n0.0 0.0\n0.5 -0.05\n1.0 0.0\n", id="lednicer-uneven"),
    ],
)  # fmt: skip
def test_each_layout_gives_the_airfoil_in_selig_order(text):
    want = SELIG if not text.startswith("T\n2.") else [SELIG[0], SELIG[2], SELIG[3], SELIG[4]]  # no upper midpoint
    np.testing.assert_array_equal(parse_dat(text, "a.dat"), want)


def test_a_lednicer_file_whose_counts_disagree_names_its_count_line():
    text = "NACA\n3. 3.\n0.0 0.0\n0.5 0.05\n1.0 0.0\n0.0 0.0\n0.5 -0.05\n"
    with pytest.raises(CurveFileError, match=r"^l\.dat:2: Lednicer counts 3 \+ 3, but 5 points follow$"):
        parse_dat(text, "l.dat")


def test_three_points_are_not_an_airfoil():
    with pytest.raises(CurveFileError, match=r"^t\.dat: 3 points; a curve needs at least 4$"):
        parse_dat("T\n1 0\n0 0\n1 0\n", "t.dat")


def test_notes_after_the_coordinates_are_skipped_with_a_warning_naming_their_line():
    text = "T\n" + "\n".join(f"{x} {y}" for x, y in SELIG) + "\n\nPolars\nalpha cl\n0 0.1\n"
    with pytest.warns(CurveFileWarning, match=r"^n\.dat:8: the coordinates end here; .*\('Polars' …\)$"):
        got = parse_dat(text, "n.dat")
    np.testing.assert_array_equal(got, SELIG)
