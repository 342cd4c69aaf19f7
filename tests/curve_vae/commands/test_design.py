"""curve_vae/commands/design.py: `curve-vae fit` and `revolve`, the geometry commands that need no model. Offline they
answer what the REST endpoints answer; they keep a user's file unless forced; revolve writes the format asked."""

from __future__ import annotations

import json
import struct

import numpy as np
import pytest

from curve_vae.cli import main
from curve_vae.geometry import evaluate_bspline

CURVE = [[0, 0], [1, 2], [2.5, 3.2], [4, 3.5], [5.5, 3], [7, 1.5], [8, 0]]


def test_fit_offline_equals_the_endpoint(client, tmp_path):
    src = tmp_path / "c.json"
    src.write_text(json.dumps([CURVE, CURVE[::-1]]))
    assert main(["fit", str(src), "--n-ctrl", "5", "--n-points", "12", "-o", str(tmp_path / "f.json")]) == 0
    rest = client.post("/fit", json={"curves": [CURVE, CURVE[::-1]], "n_ctrl": 5, "n_points": 12}).json()
    assert json.loads((tmp_path / "f.json").read_text()) == rest


def test_without_n_ctrl_fit_takes_the_fewest_control_points_within_the_tolerance(tmp_path):
    # a cubic B-spline of 7 control points that zig-zag: at the data's uniform parameters 7 fit it exactly, and
    # 4, 5 or 6 leave an error far above 0.1% of its diagonal
    ctrl = np.array([[0, 0], [10, 30], [20, -30], [30, 30], [40, -30], [50, 30], [60, 0]], np.float64)
    points = evaluate_bspline(ctrl, np.linspace(0, 1, 120))
    src = tmp_path / "c.json"
    src.write_text(json.dumps([points.tolist()]))
    assert main(["fit", str(src), "--param", "uniform", "-o", str(tmp_path / "f.json")]) == 0
    fit = json.loads((tmp_path / "f.json").read_text())["fits"][0]
    assert fit["n_ctrl"] == 7
    np.testing.assert_allclose(fit["control_points"], ctrl, atol=1e-6)
    assert main(["fit", str(src), "--param", "uniform", "--n-ctrl", "6", "-o", str(tmp_path / "six.json")]) == 0
    six = json.loads((tmp_path / "six.json").read_text())["fits"][0]
    assert six["n_ctrl"] == 6 and six["rms_error"] > 1e-3 * np.hypot(60, 60)


@pytest.mark.parametrize("command", ["fit", "revolve"])
def test_an_existing_output_is_kept_unless_forced(command, tmp_path, capsys):
    src = tmp_path / "c.json"
    src.write_text(json.dumps([CURVE]))
    out = tmp_path / ("mine.json" if command == "fit" else "mine.obj")
    out.write_text("the user's own file")
    assert main([command, str(src), "-o", str(out)]) == 2
    assert f"{out} exists and is left as it is: pass --force" in capsys.readouterr().err
    assert out.read_text() == "the user's own file"
    assert main([command, str(src), "-o", str(out), "--force"]) == 0
    assert out.read_text() != "the user's own file"


def test_revolve_writes_the_format_asked_whatever_the_files_name(tmp_path):
    # a 7-point profile clear of the axis x = -1, 12 segments: 6 bands of 12 quads, two triangles each
    src = tmp_path / "p.json"
    src.write_text(json.dumps([CURVE]))
    out = tmp_path / "surface.obj"
    assert (
        main(["revolve", str(src), "-o", str(out), "--format", "stl", "--segments", "12", "--axis-position", "-1"]) == 0
    )
    data = out.read_bytes()
    (count,) = struct.unpack_from("<I", data, 80)  # binary STL: an 80-byte header, the triangle count, 50 bytes each
    assert count == 6 * 12 * 2 and len(data) == 84 + 50 * count
    obj = tmp_path / "surface.stl"
    assert (
        main(["revolve", str(src), "-o", str(obj), "--format", "obj", "--segments", "12", "--axis-position", "-1"]) == 0
    )
    lines = obj.read_text().splitlines()
    assert (
        sum(line.startswith("v ") for line in lines) == 7 * 12 and sum(line.startswith("f ") for line in lines) == count
    )
