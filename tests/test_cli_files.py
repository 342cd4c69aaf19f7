"""The commands on the files people have (tests/fixtures/files): the page's own exports, an Inkscape drawing, a DXF
and airfoil files laid out as the UIUC database's, notes and all; and the drawings they write back."""

from __future__ import annotations

import json
import shutil
import subprocess
import sys

import ezdxf
import numpy as np
import pytest
import svgelements as se

from curve_vae.cli import main
from curve_vae.curvefiles import read_curves
from tests.helpers import FIXTURES, SHIPPED

FILES = FIXTURES / "files"

pytestmark = pytest.mark.skipif(not (SHIPPED / "manifest.json").is_file(), reason="no shipped model")


@pytest.mark.parametrize(
    "name",
    [
        "page-export.json",
        "page-export.csv",
        "page-export.dxf",
        "inkscape_drawing.svg",
        "selig_notes.dat",
        "ezdxf_drawing.dxf",
    ],
)
def test_reconstruct_gives_one_curve_back_per_curve_in(name, tmp_path, capsys):
    out = tmp_path / "out.json"
    assert main(["reconstruct", str(FILES / name), "-o", str(out)]) == 0
    given = read_curves(FILES / name)
    back = json.loads(out.read_text())["curves"]
    assert [len(c) for c in back] == [len(c) for c in given]
    err = capsys.readouterr().err
    if name.endswith(".dat"):  # the notes after the coordinates are named, not a reason to refuse the file
        assert "warning: " in err and "selig_notes.dat:72" in err and "Profilbeiwerte" in err


def test_reconstruct_draws_its_splines_as_svg_and_dxf(tmp_path):
    page = str(FILES / "page-export.json")
    spl = tmp_path / "splines.json"
    assert main(["reconstruct", page, "--output-as", "bspline", "-o", str(spl)]) == 0
    splines = json.loads(spl.read_text())["splines"]
    assert main(["reconstruct", page, "--output-as", "bspline", "-o", str(tmp_path / "out.svg")]) == 0
    paths = [e for e in se.SVG.parse(str(tmp_path / "out.svg")).elements() if isinstance(e, se.Path)]
    assert len(paths) == 4
    for path, s in zip(paths, splines):  # a cubic Bézier per knot span of the spline
        cubics = [seg for seg in path.segments() if isinstance(seg, se.CubicBezier)]
        assert len(cubics) == len(np.unique(s["knots"])) - 1
    assert main(["reconstruct", page, "--output-as", "bspline", "-o", str(tmp_path / "out.dxf")]) == 0
    entities = list(ezdxf.readfile(tmp_path / "out.dxf").modelspace().query("SPLINE"))
    assert len(entities) == 4
    for e, s in zip(entities, splines):
        np.testing.assert_allclose(np.asarray(e.control_points)[:, :2], s["control_points"], atol=1e-9)
        np.testing.assert_allclose(e.knots, s["knots"], atol=1e-12)


def test_reconstruct_writes_points_as_csv_that_reads_back(tmp_path):
    out = tmp_path / "out.csv"
    assert main(["reconstruct", str(FILES / "page-export.csv"), "-o", str(out)]) == 0
    json_out = tmp_path / "out.json"
    assert main(["reconstruct", str(FILES / "page-export.csv"), "-o", str(json_out)]) == 0
    for got, want in zip(read_curves(out), json.loads(json_out.read_text())["curves"]):
        np.testing.assert_allclose(got, want, rtol=1e-12)


def test_prior_fits_a_folder_of_airfoil_files_notes_and_all(tmp_path, capsys):
    folder = tmp_path / "airfoils"
    folder.mkdir()
    for f in FILES.glob("*.dat"):
        shutil.copy(f, folder)
    out = tmp_path / "priors" / "foils.npz"
    assert main(["prior", "--curves", str(folder), "-o", str(out), "--refine", "0"]) == 0
    err = capsys.readouterr().err
    assert "a prior of 5 curves" in err
    assert err.count("warning: ") == 3  # two notes blocks and one file of remarks, each named with its line


def test_a_file_that_is_not_curves_is_an_error_not_a_traceback(tmp_path):
    bad = tmp_path / "export.json"
    bad.write_text(json.dumps({"curves": [{"name": "A", "role": "input"}]}))
    run = subprocess.run(
        [sys.executable, "-m", "curve_vae.cli", "reconstruct", str(bad)], capture_output=True, text=True, timeout=60
    )
    assert run.returncode == 2 and "Traceback" not in run.stderr
    assert f"curve-vae reconstruct: error: {bad}: curves[0] (A) is an object without 'points'" in run.stderr


@pytest.mark.parametrize("suffix", [".svg", ".dxf", ".csv", ".npy"])
def test_sample_augment_and_fit_write_any_output_that_reads_back(suffix, tmp_path):
    made = tmp_path / f"samples{suffix}"
    assert main(["sample", "--count", "3", "--seed", "1", "--output-as", "both", "-o", str(made)]) == 0
    assert len(read_curves(made)) == 3
    mixed = tmp_path / f"mixed{suffix}"
    assert main(["augment", str(FILES / "page-export.json"), "--count", "2", "--seed", "1", "-o", str(mixed)]) == 0
    assert len(read_curves(mixed)) == 2
    if suffix in (".svg", ".dxf"):  # the fits' B-splines, drawn exactly
        fits = tmp_path / f"fits{suffix}"
        assert main(["fit", str(FILES / "inkscape_drawing.svg"), "-o", str(fits)]) == 0
        assert len(read_curves(fits)) == 3


def test_real_uiuc_files_with_notes_reconstruct_and_fit_a_prior(tmp_path, capsys):
    """hn1051.dat and hn354sm.dat as the UIUC database has them (tests/fixtures/files/README.md): coordinates, then
    a block of notes; each reads as one curve, the notes skipped with a warning naming the file and line."""
    real = FILES / "uiuc"
    for name in ("hn1051.dat", "hn354sm.dat"):
        out = tmp_path / f"{name}.json"
        assert main(["reconstruct", str(real / name), "-o", str(out)]) == 0
        body = json.loads(out.read_text())
        assert len(body["curves"]) == 1 and len(body["curves"][0]) > 50
        err = capsys.readouterr().err
        assert f"{name}:" in err and "Profilbeiwerte" in err
    prior = tmp_path / "uiuc.npz"
    assert main(["prior", "--curves", str(real), "-o", str(prior), "--refine", "0"]) == 0
    assert prior.stat().st_size > 0
