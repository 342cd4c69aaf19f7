"""Offline commands on real files: fit and revolve (no model), what every writing command does to existing files,
and the curve file formats."""

import json

import numpy as np
import pytest

from curve_vae.cli import main
from curve_vae.curvefiles import read_curves
from curve_vae.geometry import random_control_points, sample_bspline


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


@pytest.mark.parametrize(
    "command",
    [
        pytest.param(["fit", "{src}", "-o", "{out}"], id="fit"),
        pytest.param(["revolve", "{profile}", "-o", "{out}"], id="revolve"),
        pytest.param(["sample", "--count", "2", "-o", "{out}"], id="sample"),
        pytest.param(["augment", "{src}", "--count", "2", "-o", "{out}"], id="augment"),
    ],
)
def test_no_command_overwrites_a_users_file_without_force(command, curve_file, tmp_path, capsys):
    path, _ = curve_file
    profile = tmp_path / "p.json"
    profile.write_text(json.dumps([[0, 0], [2, 0], [3, 1], [2, 3]]))
    out = tmp_path / "mine.json"
    out.write_text("the user's own file")
    args = [a.format(src=path, profile=profile, out=out) for a in command]
    assert main(args) == 2
    assert out.read_text() == "the user's own file"
    assert f"{out} exists and is left as it is: pass --force" in capsys.readouterr().err
    assert main([*args, "--force"]) == 0
    assert out.read_text() != "the user's own file"


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


def test_revolve_takes_the_body_the_endpoint_takes(tmp_path):
    """`curve-vae revolve` reads the JSON POST /revolve takes: {"curve": […], …}."""
    body = tmp_path / "revolve.json"
    body.write_text(json.dumps({"curve": [[0, 0], [2, 0], [3, 1], [2, 3]], "segments": 10}))
    out = tmp_path / "vase.obj"
    assert main(["revolve", str(body), "-o", str(out), "--segments", "10", "--axis-position", "0"]) == 0
    assert sum(line.startswith("v ") for line in out.read_text().splitlines()) == 1 + 3 * 10


def test_the_papers_model_is_reachable_by_name_from_anywhere(tmp_path, monkeypatch):
    """`--model paper` names the model shipped inside the package, whatever the working directory."""
    from curve_vae.inference.models import NAMED, model_directory
    from curve_vae.service.settings import Settings

    monkeypatch.chdir(tmp_path)
    assert model_directory("paper") == NAMED["paper"] and (NAMED["paper"] / "manifest.json").is_file()
    assert Settings(model_dir="paper").model_dir == NAMED["paper"]
    out = tmp_path / "s.json"
    assert main(["sample", "--model", "paper", "--count", "2", "--seed", "1", "-o", str(out)]) == 0
    assert len(json.loads(out.read_text())["curves"]) == 2


def test_help_summarises_the_whole_command_line():
    """`curve-vae --help` opens with a whole sentence, and the module's list names every command."""
    import subprocess
    import sys

    import curve_vae.cli as cli

    out = subprocess.run([sys.executable, "-m", "curve_vae.cli", "--help"], capture_output=True, text=True, timeout=60)
    summary = " ".join(out.stdout.split("positional arguments")[0].split("\n", 2)[2].split())
    assert out.returncode == 0 and summary.endswith("fit priors to your own."), summary
    commands = cli.build_parser()._subparsers._group_actions[0].choices  # type: ignore[union-attr]
    listed = cli.__doc__.split("Commands:")[1]
    assert [name for name in commands if name not in listed] == []
