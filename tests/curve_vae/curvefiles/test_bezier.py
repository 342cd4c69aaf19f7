"""curve_vae.curvefiles.bezier: a clamped cubic B-spline as cubic Bézier segments is the same curve (against scipy's
own B-spline), a one-span spline is its own Bézier, and the points along segments are Bernstein's."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.interpolate import BSpline

from curve_vae.curvefiles import CurveFileError, bezier_points, spline_beziers


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


def test_a_one_span_spline_is_its_own_bezier():
    ctrl = [[0.0, 0.0], [1.0, 3.0], [4.0, 3.0], [5.0, -1.0]]
    np.testing.assert_allclose(spline_beziers(ctrl, [0, 0, 0, 0, 1, 1, 1, 1]), [ctrl], atol=1e-12)


def test_segments_join_where_the_spline_passes_its_knots():
    s = _spline(7, n=9)
    segments = spline_beziers(s["control_points"], s["knots"])
    np.testing.assert_allclose(segments[1:, 0], segments[:-1, 3], atol=1e-12)  # C0: each starts where one ends
    inner = np.unique(s["knots"])[1:-1]
    exact = BSpline(np.asarray(s["knots"]), np.asarray(s["control_points"]), 3)(inner)
    np.testing.assert_allclose(segments[1:, 0], exact, atol=1e-12)


@pytest.mark.parametrize(
    ("ctrl", "knots", "degree", "message"),
    [
        pytest.param([[0, 0]] * 4, [0, 0, 0, 1, 1, 1, 1], 2, "a B-spline of degree 2: Bézier paths", id="quadratic"),
        pytest.param([[0, 0]] * 4, [0, 0, 0, 0, 1, 1, 1], 3, r"n \+ 4 knots, got \(4, 2\) and 7", id="knots"),
        pytest.param([[0, 0, 0]] * 4, [0] * 4 + [1] * 4, 3, r"got \(4, 3\) and 8", id="3d-points"),
    ],
)
def test_what_is_not_a_cubic_spline_of_2d_points_is_refused(ctrl, knots, degree, message):
    with pytest.raises(CurveFileError, match=message):
        spline_beziers(ctrl, knots, degree)


def test_points_along_segments_are_bernsteins_with_each_join_once():
    seg = np.array(
        [[[0.0, 0.0], [1.0, 2.0], [3.0, 2.0], [4.0, 0.0]], [[4.0, 0.0], [5.0, -2.0], [7.0, -2.0], [8.0, 0.0]]]
    )
    pts = bezier_points(seg, per_segment=2)
    mid = lambda p: (p[0] + 3 * p[1] + 3 * p[2] + p[3]) / 8  # noqa: E731  # B(1/2)
    np.testing.assert_allclose(pts, [seg[0, 0], mid(seg[0]), seg[0, 3], mid(seg[1]), seg[1, 3]], atol=1e-15)
    assert len(bezier_points(seg, 16)) == 1 + 2 * 16
