"""curve_vae.curvefiles.writing: an answer written by its file's extension (.json, .csv, .npy, .svg, .dxf, - for
stdout) reads back as the same curves, atomically; what a format cannot hold is refused before anything is written.
(The drawings' own contents: test_svg.py, test_dxf.py.)"""

from __future__ import annotations

import json

import numpy as np
import pytest
import svgelements as se

from curve_vae.curvefiles import CurveFileError, read_curves, write_output


def _spline(seed: int, n: int = 31, *, repeated: bool = False) -> dict:
    rng = np.random.default_rng(seed)
    inner = np.sort(rng.uniform(0, 1, n - 4))
    if repeated:
        inner[5] = inner[6]  # a double knot: the spline is only C1 there
    knots = np.r_[[0.0] * 4, inner, [1.0] * 4]
    return {"control_points": rng.normal(size=(n, 2)).tolist(), "knots": knots.tolist(), "degree": 3}


CURVES = [np.column_stack([np.linspace(0, 3, 6), np.sin(np.linspace(0, 3, 6))]) + k for k in range(3)]


@pytest.mark.parametrize("suffix", [".csv", ".npy", ".svg", ".dxf", ".json"])
def test_points_written_in_any_format_read_back(tmp_path, suffix):
    out = tmp_path / f"out{suffix}"
    write_output(str(out), {"curves": [c.tolist() for c in CURVES], "mse": [0.0] * 3}, array_key="curves")
    back = read_curves(out)
    atol = 1e-6 if suffix == ".npy" else 1e-9  # .npy is float32
    assert len(back) == 3
    for got, c in zip(back, CURVES):
        np.testing.assert_allclose(got, c, atol=atol)
    assert [p.name for p in tmp_path.iterdir()] == [out.name]  # written beside and renamed: nothing else left


def test_what_a_format_cannot_hold_is_refused(tmp_path):
    ragged = {"curves": [CURVES[0].tolist(), CURVES[0][:5].tolist()]}
    with pytest.raises(CurveFileError, match="different lengths"):
        write_output(str(tmp_path / "r.npy"), ragged, array_key="curves")
    with pytest.raises(CurveFileError, match=r"no curves' points to write as \.csv \(ask for points"):
        write_output(str(tmp_path / "s.csv"), {"splines": [_spline(1)]})
    with pytest.raises(CurveFileError, match=r"no curves' points to write as \.svg"):
        write_output(str(tmp_path / "latents.svg"), {"mean": [[0.0]], "log_var": [[0.0]]})
    assert list(tmp_path.iterdir()) == []


def test_csv_rows_are_curve_index_x_y_with_every_digit(tmp_path):
    out = tmp_path / "out.csv"
    write_output(str(out), {"curves": [[[0, 0.1], [1, 2]], [[1 / 3, -2.5e-7]]]})
    assert out.read_text() == "curve,index,x,y\n0,0,0.0,0.1\n0,1,1.0,2.0\n1,0,0.3333333333333333,-2.5e-07\n"


def test_npy_holds_the_named_array_as_float32(tmp_path):
    out = tmp_path / "latents.npy"
    write_output(str(out), {"mean": [[0.5, 1.25], [2.0, -1.0]], "curves": [[[9, 9]]]}, array_key="mean")
    got = np.load(out)
    assert got.dtype == np.float32 and got.tolist() == [[0.5, 1.25], [2.0, -1.0]]


@pytest.mark.parametrize("target", ["-", "out.json", "out.txt"], ids=["stdout", "json", "other-suffix"])
def test_json_is_the_answer_compact_to_a_file_or_stdout(tmp_path, capsys, monkeypatch, target):
    monkeypatch.chdir(tmp_path)
    payload = {"curves": [[[0.0, 1.5]]], "mse": [0.25]}
    write_output(target, payload)
    text = capsys.readouterr().out if target == "-" else (tmp_path / target).read_text()
    assert text == '{"curves":[[[0.0,1.5]]],"mse":[0.25]}\n' and json.loads(text) == payload


def test_a_fits_answer_draws_each_fit_as_beziers(tmp_path):
    """`curve-vae fit` answers `fits`: an .svg of it draws a cubic per knot span of each."""
    fits = [_spline(1, n=10), _spline(2, n=6)]
    write_output(str(tmp_path / "fits.svg"), {"fits": fits})
    paths = [e for e in se.SVG.parse(str(tmp_path / "fits.svg")).elements() if isinstance(e, se.Path)]
    assert [sum(isinstance(s, se.CubicBezier) for s in p.segments()) for p in paths] == [10 - 3, 6 - 3]
