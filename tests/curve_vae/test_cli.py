"""The `curve-vae` command line (curve_vae.cli and the commands it assembles): the offline commands (fit, revolve) on
real files, the commands on the files people have (tests/fixtures/files: the page's own exports, an Inkscape drawing,
a DXF, airfoil files laid out as the UIUC database's, notes and all) and the drawings they write back, the same
commands against a live server (`--server URL`), and what the user sees when something is wrong: one line naming it
and exit status 2, never a traceback."""

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
from curve_vae.client import ApiError
from curve_vae.curvefiles import read_curves
from curve_vae.errors import InvalidInput
from curve_vae.geometry import random_control_points, sample_bspline
from curve_vae.inference.model.manifest import ModelLoadError
from tests.helpers import FIXTURES, ROOT, SHIPPED

FILES = FIXTURES / "files"
NEEDS_SHIPPED = pytest.mark.skipif(not (SHIPPED / "manifest.json").is_file(), reason="no shipped model")


@pytest.fixture
def curve_file(tmp_path):
    ctrl = random_control_points(np.random.default_rng(0), 2)
    path = tmp_path / "curves.json"
    path.write_text(json.dumps({"curves": sample_bspline(ctrl).tolist()}))
    return path, ctrl


def test_fit_recovers_control_points(curve_file, tmp_path):
    path, ctrl = curve_file
    out = tmp_path / "fit.json"
    assert main(["fit", str(path), "-o", str(out), "--param", "uniform"]) == 0
    fits = json.loads(out.read_text())["fits"]
    assert len(fits) == 2
    np.testing.assert_allclose(np.array(fits[1]["control_points"]), ctrl[1], atol=1e-6)
    assert len(fits[0]["knots"]) == 14


def test_fit_reads_npy_and_reports_bad_input(tmp_path, capsys):
    np.save(tmp_path / "c.npy", np.array([[0, 0], [1, 2], [2, 1], [3, 3.0]] * 3))
    assert main(["fit", str(tmp_path / "c.npy"), "--n-ctrl", "4"]) == 0
    bad = tmp_path / "bad.json"
    bad.write_text('[[0, 0], [1, "x"]]')
    assert main(["fit", str(bad)]) == 2
    assert "curve-vae fit: error" in capsys.readouterr().err


@pytest.mark.parametrize("fmt", ["obj", "stl"])
def test_revolve_writes_mesh(tmp_path, fmt):
    prof = tmp_path / "p.json"
    prof.write_text(json.dumps([[0, 0], [2, 0], [3, 1], [2, 3]]))
    out = tmp_path / f"vase.{fmt}"
    assert main(["revolve", str(prof), "-o", str(out), "--segments", "10", "--axis-position", "0"]) == 0
    if fmt == "obj":
        lines = out.read_text().splitlines()
        assert sum(line.startswith("v ") for line in lines) == 1 + 3 * 10
        assert sum(line.startswith("f ") for line in lines) == 10 + 2 * 2 * 10
    else:
        data = out.read_bytes()
        assert int.from_bytes(data[80:84], "little") == 50 and len(data) == 84 + 50 * 50


def test_revolve_rejects_several_profiles(curve_file, tmp_path, capsys):
    path, _ = curve_file
    assert main(["revolve", str(path), "-o", str(tmp_path / "x.obj")]) == 2
    assert "one profile curve" in capsys.readouterr().err


def test_revolve_takes_the_body_the_endpoint_takes(tmp_path):
    """`curve-vae revolve` reads the JSON POST /revolve takes: {"curve": […], …}."""
    body = tmp_path / "revolve.json"
    body.write_text(json.dumps({"curve": [[0, 0], [2, 0], [3, 1], [2, 3]], "segments": 10}))
    out = tmp_path / "vase.obj"
    assert main(["revolve", str(body), "-o", str(out), "--segments", "10", "--axis-position", "0"]) == 0
    assert sum(line.startswith("v ") for line in out.read_text().splitlines()) == 1 + 3 * 10


def test_the_papers_model_is_reachable_by_name_from_anywhere(tmp_path, monkeypatch):
    """`--model paper` names the model shipped inside the package, whatever the working directory."""
    from curve_vae.inference.model.shipped import NAMED, model_directory
    from curve_vae.service.settings import Settings

    monkeypatch.chdir(tmp_path)
    assert model_directory("paper") == NAMED["paper"] and (NAMED["paper"] / "manifest.json").is_file()
    assert Settings(model_dir="paper").model_dir == NAMED["paper"]
    out = tmp_path / "s.json"
    assert main(["sample", "--model", "paper", "--count", "2", "--seed", "1", "-o", str(out)]) == 0
    assert len(json.loads(out.read_text())["curves"]) == 2


def test_help_summarises_the_whole_command_line():
    """`curve-vae --help` opens with a whole sentence, and the module's list names every command."""
    import curve_vae.cli as cli

    out = subprocess.run([sys.executable, "-m", "curve_vae.cli", "--help"], capture_output=True, text=True, timeout=60)
    summary = " ".join(out.stdout.split("positional arguments")[0].split("\n", 2)[2].split())
    assert out.returncode == 0 and summary.endswith("fit priors to your own."), summary
    commands = cli.build_parser()._subparsers._group_actions[0].choices  # type: ignore[union-attr]
    listed = cli.__doc__.split("Commands:")[1]
    assert [name for name in commands if name not in listed] == []


def test_version_is_the_projects():
    """`curve-vae --version` names the version pyproject.toml gives the project."""
    import tomllib

    want = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["version"]
    run = subprocess.run(
        [sys.executable, "-m", "curve_vae.cli", "--version"], capture_output=True, text=True, timeout=60
    )
    assert run.returncode == 0 and run.stdout.strip() == f"curve-vae {want}"


@pytest.mark.parametrize(
    ("body", "says"),
    [
        pytest.param(None, "{path}: no such file", id="missing-input"),
        pytest.param("[[0, 0], [1, NaN], [2, 1], [3, 3]]", "{path}: curve 0 point 1 is not finite", id="nan-point"),
        pytest.param(
            "[[0, 0], [1, 2], [2, 1]]", "{path}: curve 0 has 3 points; a curve needs at least 4", id="3-points"
        ),
    ],
)
def test_bad_input_is_one_line_naming_the_file_and_status_2(tmp_path, capsys, body, says):
    path = tmp_path / "curves.json"
    if body is not None:
        path.write_text(body)
    assert main(["fit", str(path), "-o", str(tmp_path / "fit.json")]) == 2
    err = capsys.readouterr().err
    assert err.splitlines() == ["curve-vae fit: error: " + says.format(path=path)]
    assert not (tmp_path / "fit.json").exists()


def test_an_output_that_cannot_be_written_is_an_error_naming_it(tmp_path, capsys):
    """An OSError (here: the output's folder is a file) is the command's error, not a traceback."""
    (tmp_path / "taken").write_text("a file, not a folder")
    out = tmp_path / "taken" / "fit.json"
    assert main(["fit", str(FILES / "selig_fortran.dat"), "-o", str(out)]) == 2
    (line,) = capsys.readouterr().err.splitlines()
    assert line.startswith("curve-vae fit: error: ") and str(tmp_path / "taken") in line
    assert (tmp_path / "taken").read_text() == "a file, not a folder"


def test_what_a_reader_skips_is_one_warning_line_and_the_command_goes_on(tmp_path, capsys):
    """The notes after an airfoil's coordinates: a line naming the file and the line they start on (found here in the
    file itself), not Python's warning with its source line; the airfoil is still fitted."""
    name = FILES / "selig_notes.dat"
    start = name.read_text().splitlines().index("Profilbeiwerte") + 1
    out = tmp_path / "fit.json"
    assert main(["fit", str(name), "-o", str(out)]) == 0
    warnings = [line for line in capsys.readouterr().err.splitlines() if "warning" in line]
    assert warnings == [
        f"curve-vae fit: warning: {name}:{start}: the coordinates end here; the lines from here on are skipped "
        "('Profilbeiwerte' …)"
    ]
    assert len(json.loads(out.read_text())["fits"]) == 1


# ------------------------------------------------------------------ the files people have


@NEEDS_SHIPPED
@pytest.mark.parametrize(
    "name",
    [
        "page-export.json",
        "page-export.csv",
        "page-export.svg",
        "page-export.dxf",
        "page-sheet.svg",
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
    if name.startswith("page-export"):  # the drawing's three inputs, from each of the page's exports
        assert len(back) == 3
        assert "warning: " in err and "its 3 input curve(s) read; 14 derived curve(s)" in err
    if name.endswith(".dat"):  # the notes after the coordinates are named, not a reason to refuse the file
        assert "warning: " in err and "selig_notes.dat:72" in err and "Profilbeiwerte" in err


@NEEDS_SHIPPED
def test_reconstruct_draws_its_inputs_and_splines_as_svg_and_dxf_as_the_page_does(tmp_path):
    """A reconstruction drawn as SVG or DXF holds what the page's export holds: each input named A, B, C (role input,
    the page's colour), then its reconstruction (of its input, in its colour), a B-spline drawn exactly; opened
    again, the inputs are read (the reconstructions are derived)."""
    from curve_vae.curvefiles.roles import PALETTE, PALETTE_ACI

    page = str(FILES / "page-export.json")
    inputs = read_curves(page)
    spl = tmp_path / "splines.json"
    assert main(["reconstruct", page, "--output-as", "bspline", "-o", str(spl)]) == 0
    splines = json.loads(spl.read_text())["splines"]
    assert main(["reconstruct", page, "--output-as", "bspline", "-o", str(tmp_path / "out.svg")]) == 0
    paths = [e for e in se.SVG.parse(str(tmp_path / "out.svg")).elements() if isinstance(e, se.Path)]
    assert len(paths) == 2 * len(splines) == 6
    for k, path in enumerate(paths[:3]):  # the inputs, as given
        assert path.values["class"] == "input" and path.values["data-name"] == "ABC"[k]
        assert path.values["stroke"] == PALETTE[k]
    for k, (path, s) in enumerate(zip(paths[3:], splines)):  # a cubic Bézier per knot span of the spline
        assert path.values["class"] == "reconstruction" and path.values["data-of"] == "ABC"[k]
        assert path.values["stroke"] == PALETTE[k]
        cubics = [seg for seg in path.segments() if isinstance(seg, se.CubicBezier)]
        assert len(cubics) == len(np.unique(s["knots"])) - 1
    with pytest.warns(UserWarning, match="its 3 input curve"):
        again = read_curves(tmp_path / "out.svg")
    for got, want in zip(again, inputs):
        np.testing.assert_allclose(got, want, rtol=1e-9, atol=1e-9)
    assert main(["reconstruct", page, "--output-as", "bspline", "-o", str(tmp_path / "out.dxf")]) == 0
    doc = ezdxf.readfile(tmp_path / "out.dxf")
    entities = list(doc.modelspace().query("SPLINE"))
    assert len(entities) == 3 and len(doc.modelspace().query("LWPOLYLINE")) == 3
    for k, (e, s) in enumerate(zip(entities, splines)):
        np.testing.assert_allclose(np.asarray(e.control_points)[:, :2], s["control_points"], atol=1e-9)
        np.testing.assert_allclose(e.knots, s["knots"], atol=1e-12)
        assert doc.layers.get(e.dxf.layer).color == PALETTE_ACI[k]


@NEEDS_SHIPPED
def test_reconstruct_writes_points_as_csv_that_reads_back(tmp_path):
    out = tmp_path / "out.csv"
    assert main(["reconstruct", str(FILES / "page-export.csv"), "-o", str(out)]) == 0
    json_out = tmp_path / "out.json"
    assert main(["reconstruct", str(FILES / "page-export.csv"), "-o", str(json_out)]) == 0
    for got, want in zip(read_curves(out), json.loads(json_out.read_text())["curves"]):
        np.testing.assert_allclose(got, want, rtol=1e-12)


@NEEDS_SHIPPED
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


@NEEDS_SHIPPED
def test_a_file_that_is_not_curves_is_an_error_not_a_traceback(tmp_path):
    bad = tmp_path / "export.json"
    bad.write_text(json.dumps({"curves": [{"name": "A", "role": "input"}]}))
    run = subprocess.run(
        [sys.executable, "-m", "curve_vae.cli", "reconstruct", str(bad)], capture_output=True, text=True, timeout=60
    )
    assert run.returncode == 2 and "Traceback" not in run.stderr
    assert f"curve-vae reconstruct: error: {bad}: curves[0] (A) is an object without 'points'" in run.stderr


@NEEDS_SHIPPED
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


@NEEDS_SHIPPED
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


# ------------------------------------------------------------------ --server URL

C = [
    [[0, 0], [1, 2], [2.5, 3.2], [4, 3.5], [5.5, 3], [7, 1.5], [8, 0]],
    [[0, 0], [1.5, 0.5], [3, 2], [4, 4], [5, 6.5], [6.5, 8], [8, 8.5]],
    [[0, 4], [2, 5], [4, 4], [6, 2], [8, 1], [10, 2], [12, 4]],
]


def _close(a, b) -> None:
    """JSON bodies equal, numbers to float rounding (the server's onnxruntime threads may differ)."""
    if isinstance(a, dict):
        assert set(a) == set(b), (set(a), set(b))
        for k in a:
            _close(a[k], b[k])
    elif isinstance(a, list) and a and isinstance(a[0], (list, dict)):
        assert len(a) == len(b)
        for x, y in zip(a, b):
            _close(x, y)
    elif isinstance(a, (int, float)) and not isinstance(a, bool) or (isinstance(a, list) and a):
        np.testing.assert_allclose(np.asarray(a, float), np.asarray(b, float), rtol=1e-6, atol=1e-9)
    else:
        assert a == b


@pytest.mark.parametrize(
    "command",
    [
        pytest.param(["sample", "--count", "5", "--seed", "3", "--n-points", "20"], id="sample"),
        pytest.param(["sample", "--count", "3", "--seed", "4", "--output-as", "both", "--metrics"], id="sample-both"),
        pytest.param(["augment", "IN", "--count", "300", "--seed", "2", "--mode", "triplet"], id="augment-json"),
        pytest.param(["augment", "IN", "--count", "300", "--seed", "2", "-o", "OUT.npy"], id="augment-npy"),
        pytest.param(["reconstruct", "IN", "--output-as", "both", "--metrics"], id="reconstruct"),
        pytest.param(["encode", "IN", "--pose", "as_is"], id="encode"),
        pytest.param(["fit", "IN", "--n-ctrl", "5", "--n-points", "9"], id="fit"),
    ],
)
def test_server_output_equals_the_local_commands(live_server, model_dir, tmp_path, command):
    (tmp_path / "in.json").write_text(json.dumps(C))
    outs = []
    for where in (["--model-dir", str(model_dir)], ["--server", live_server.url]):
        out = tmp_path / f"out{len(outs)}{'.npy' if 'OUT.npy' in command else '.json'}"
        argv = [str(tmp_path / "in.json") if x == "IN" else x for x in command if x not in ("-o", "OUT.npy")]
        if command[0] in ("fit",):
            where = where if where[0] == "--server" else []
        assert main([*argv, "-o", str(out), *where, *(["--no-progress"] if command[0] == "augment" else [])]) == 0
        outs.append(out)
    if outs[0].suffix == ".npy":
        np.testing.assert_allclose(np.load(outs[0]), np.load(outs[1]), rtol=1e-5, atol=1e-5)
    else:
        _close(json.loads(outs[0].read_text()), json.loads(outs[1].read_text()))


def test_revolve_on_a_server_writes_the_same_mesh(live_server, tmp_path):
    (tmp_path / "p.json").write_text(json.dumps([[0, 0], [3, 0], [4, 1], [3, 3], [0, 5]]))
    for fmt in ("obj", "stl"):
        local, remote = tmp_path / f"a.{fmt}", tmp_path / f"b.{fmt}"
        assert main(["revolve", str(tmp_path / "p.json"), "-o", str(local), "--segments", "16"]) == 0
        assert (
            main(
                [
                    "revolve",
                    str(tmp_path / "p.json"),
                    "-o",
                    str(remote),
                    "--segments",
                    "16",
                    "--server",
                    live_server.url,
                ]
            )
            == 0
        )
        assert local.read_bytes() == remote.read_bytes()


def test_a_refusal_of_the_server_is_the_commands_error(live_server, tmp_path, capsys):
    (tmp_path / "in.json").write_text(json.dumps(C[:2]))
    assert (
        main(["augment", str(tmp_path / "in.json"), "--count", "5", "--mode", "triplet", "--server", live_server.url])
        == 2
    )
    assert "422: curves: mode triplet needs at least 3 curves, got 2" in capsys.readouterr().err


@pytest.mark.parametrize(
    ("raised", "exits"),
    [
        pytest.param(InvalidInput("curves: all points coincide"), True, id="input"),
        pytest.param(ModelLoadError("models/x: manifest.json is missing"), True, id="model"),
        pytest.param(ApiError(422, "curves: at most 4 curves per request, got 5"), True, id="client"),
        pytest.param(FileNotFoundError(2, "No such file or directory", "in.json"), True, id="file"),
        pytest.param(ValueError("operands could not be broadcast together"), False, id="bug-value"),
        pytest.param(KeyError("mean"), False, id="bug-key"),
    ],
)
def test_what_the_project_raises_is_one_line_and_a_bug_keeps_its_traceback(monkeypatch, capsys, raised, exits):
    """curve-vae prints a CurveVaeError or an OSError as `curve-vae CMD: error: …` with exit 2; anything else is not
    the user's doing and propagates, traceback and all."""
    from curve_vae.commands import curves

    def fails(_args):
        raise raised

    monkeypatch.setattr(curves, "cmd_encode", fails)
    if exits:
        assert main(["encode", "in.json"]) == 2
        err = capsys.readouterr().err
        assert err.startswith("curve-vae encode: error: ") and err.count("\n") == 1
    else:
        with pytest.raises(type(raised)):
            main(["encode", "in.json"])
