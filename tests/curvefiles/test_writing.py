"""curve_vae.curvefiles' writers: B-splines as exact Bézier paths and SPLINE entities, points as CSV, NPY and
polylines; each read back by a parser that did not write it (svgelements, ezdxf) and by the reader."""

from __future__ import annotations

import ezdxf
import numpy as np
import pytest
import svgelements as se
from scipy.interpolate import BSpline

from curve_vae.curvefiles import CurveFileError, read_curves, spline_beziers, write_output
from curve_vae.curvefiles.bezier import bezier_points


def _spline(seed: int, n: int = 31, *, repeated: bool = False) -> dict:
    rng = np.random.default_rng(seed)
    inner = np.sort(rng.uniform(0, 1, n - 4))
    if repeated:
        inner[5] = inner[6]  # a double knot: the spline is only C1 there
    knots = np.r_[[0.0] * 4, inner, [1.0] * 4]
    return {"control_points": rng.normal(size=(n, 2)).tolist(), "knots": knots.tolist(), "degree": 3}


@pytest.mark.parametrize("repeated", [False, True], ids=["simple-knots", "double-knot"])
def test_a_bspline_as_bezier_segments_is_the_same_curve(repeated):
    s = _spline(1, repeated=repeated)
    segments = spline_beziers(s["control_points"], s["knots"])
    spans = np.unique(s["knots"])
    assert segments.shape == (len(spans) - 1, 4, 2)
    per = 12
    u = np.concatenate(
        [spans[:1], (spans[:-1, None] + np.diff(spans)[:, None] * np.linspace(0, 1, per + 1)[1:]).ravel()]
    )
    exact = BSpline(np.asarray(s["knots"]), np.asarray(s["control_points"]), 3)(u)
    np.testing.assert_allclose(bezier_points(segments, per), exact, atol=1e-12)


def _user(undo: se.Matrix, p: se.Point) -> tuple[float, float]:
    """A point of the parsed drawing in its viewBox's units, y up."""
    q = undo.point_in_matrix_space(p)
    return q.x, -q.y


def test_svg_of_splines_is_one_path_of_exact_cubics_per_curve(tmp_path):
    splines = [_spline(2), _spline(3, n=12)]
    out = tmp_path / "out.svg"
    write_output(str(out), {"splines": splines, "mse": [0.1, 0.2]})
    svg = se.SVG.parse(str(out))
    undo = ~se.Matrix(svg.viewbox_transform)
    paths = [e for e in svg.elements() if isinstance(e, se.Path)]
    assert len(paths) == 2
    for path, s in zip(paths, splines):
        cubics = [seg for seg in path.segments() if isinstance(seg, se.CubicBezier)]
        got = np.array(
            [
                [
                    [(undo.point_in_matrix_space(p)).x, -(undo.point_in_matrix_space(p)).y]
                    for p in (c.start, c.control1, c.control2, c.end)
                ]
                for c in cubics
            ]
        )
        np.testing.assert_allclose(got, spline_beziers(s["control_points"], s["knots"]), atol=1e-8)
    assert [len(c) for c in read_curves(out)] == [1 + 16 * 28, 1 + 16 * 9]  # n - 3 spans of 16 points


def test_dxf_of_splines_holds_their_control_points_and_knots(tmp_path):
    splines = [_spline(4), _spline(5, n=8)]
    out = tmp_path / "out.dxf"
    write_output(str(out), {"splines": splines})
    entities = list(ezdxf.readfile(out).modelspace().query("SPLINE"))
    assert len(entities) == 2
    for e, s in zip(entities, splines):
        assert e.dxf.degree == 3
        np.testing.assert_allclose(np.asarray(e.control_points)[:, :2], s["control_points"], atol=1e-12)
        np.testing.assert_allclose(e.knots, s["knots"], atol=1e-12)
    curves = read_curves(out)
    exact = BSpline(np.asarray(splines[0]["knots"]), np.asarray(splines[0]["control_points"]), 3)
    np.testing.assert_allclose(curves[0][[0, -1]], exact([0.0, 1.0]), atol=1e-9)


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
