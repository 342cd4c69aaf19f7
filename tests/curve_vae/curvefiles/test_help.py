"""curve_vae.curvefiles.help: the kinds of curve file the commands' help names are the kinds the readers read and
the writers write; every one named, and a file of every kind read."""

from __future__ import annotations

import shutil

import numpy as np
import pytest

from curve_vae.curvefiles import read_curves, write_output
from curve_vae.curvefiles.help import CURVE_SUFFIXES, INPUT_HELP, OUTPUT_HELP, OUTPUT_SUFFIXES
from tests.helpers import FIXTURES

FILES = FIXTURES / "files"
SQUARE_WAVE = np.array([[0, 0], [1, 1], [2, 0], [3, 1]], float)


def test_the_help_names_every_kind_read_and_written():
    assert [s for s in CURVE_SUFFIXES if s not in INPUT_HELP] == []
    assert [s for s in OUTPUT_SUFFIXES if s not in OUTPUT_HELP] == []


def test_what_is_written_can_be_read_back_in():
    assert set(OUTPUT_SUFFIXES) <= set(CURVE_SUFFIXES)


@pytest.mark.parametrize("suffix", CURVE_SUFFIXES)
def test_a_file_of_each_kind_named_is_read(tmp_path, suffix):
    """Each kind by its own reader: the fixtures of the drawings and airfoils, the rest written here."""
    path = tmp_path / f"c{suffix}"
    fixture = {".svg": "inkscape_drawing.svg", ".dxf": "ezdxf_drawing.dxf", ".dat": "selig_fortran.dat"}
    if suffix in fixture:
        shutil.copy(FILES / fixture[suffix], path)
        assert len(read_curves(path)) >= 1
        return
    if suffix == ".tsv":
        path.write_text("x\ty\n" + "".join(f"{x:g}\t{y:g}\n" for x, y in SQUARE_WAVE))
    elif suffix == ".npz":
        np.savez(path, curves=SQUARE_WAVE[None])
    else:
        write_output(str(path), {"curves": [SQUARE_WAVE.tolist()]})
    (curve,) = read_curves(path)
    np.testing.assert_array_equal(curve, SQUARE_WAVE)


def test_an_airfoil_may_come_as_txt(tmp_path):
    """.txt is read as .dat (airfoil coordinates come as either); the help names .dat alone."""
    shutil.copy(FILES / "selig_fortran.dat", tmp_path / "foil.txt")
    np.testing.assert_array_equal(read_curves(tmp_path / "foil.txt")[0], read_curves(FILES / "selig_fortran.dat")[0])
