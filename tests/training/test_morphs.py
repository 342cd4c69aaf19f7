"""training/morphs.py: the morph suite. Pairs of curves drawn in one pose of their own, each sweep measured by its
chords' turn and its end points' drift, beside point-wise blending and /reconstruct's answers; its table."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from curve_vae.training.morphs import DRIFT_LIMIT, TURN_LIMIT, format_morphs, morph_pairs, run_morphs, sweep_measures
from tests.helpers import bspline_curves


def test_each_pair_is_moved_by_one_similarity_flipped_to_y_down():
    test = bspline_curves(5, seed=1)
    pairs = morph_pairs(test, count=4, seed=7)
    assert len(pairs) == 4
    for i, (a, b) in enumerate(pairs):
        src_a, src_b = test[(2 * i) % 5], test[(2 * i + 1) % 5]  # consecutive curves, wrapping round the set
        # one similarity for both: every distance between their points is scaled by one factor
        scale = np.linalg.norm(a[0] - b[-1]) / np.linalg.norm(src_a[0] - src_b[-1])
        np.testing.assert_allclose(np.linalg.norm(a - b, axis=1), scale * np.linalg.norm(src_a - src_b, axis=1))
        assert 2 <= scale <= 6
        # a y flip turns the curve's way round: the signed area changes sign
        area = lambda c: np.cross(c[1:] - c[0], c[:-1] - c[0]).sum()  # noqa: E731
        assert np.sign(area(a)) == -np.sign(area(src_a))
    again = morph_pairs(test, count=4, seed=7)
    assert all(np.array_equal(x, y) for p, q in zip(pairs, again) for x, y in zip(p, q))


def _line(start, end, n=5):
    return np.linspace(start, end, n)


def test_a_sweep_of_a_shape_moved_along_its_own_line_neither_turns_nor_drifts():
    sweep = np.stack([_line([t, 0.0], [t + 10.0, 0.0]) for t in np.linspace(0, 4, 5)])
    m = sweep_measures([sweep])
    assert m["turn_excess_max_deg"] == pytest.approx(0.0) and m["end_drift_max"] == pytest.approx(0.0)
    assert m["share_turning_beyond_limit"] == 0.0 and m["share_drifting_beyond_limit"] == 0.0


def test_a_sweep_whose_middle_turns_and_strays_is_counted_beyond_the_limits():
    ends = _line([0.0, 0.0], [10.0, 0.0])
    middle = _line([5.0, -5.0], [5.0, 5.0])  # its chord at 90° to both ends', its ends 5 off theirs
    sweep = np.stack([ends, middle, ends])
    m = sweep_measures([sweep, np.stack([ends, ends, ends])])
    assert m["turn_excess_max_deg"] == pytest.approx(90.0) and m["turn_excess_mean_deg"] == pytest.approx(45.0)
    # both ends the same curve: the "segment" between their first points is (0, 0), and (5, -5) is √50 from it; the
    # ends' joint bounding box is 10 × 0
    assert m["end_drift_max"] == pytest.approx(np.hypot(5, 5) / 10)
    assert 90.0 > TURN_LIMIT and 0.5 > DRIFT_LIMIT
    assert m["share_turning_beyond_limit"] == 0.5 and m["share_drifting_beyond_limit"] == 0.5


class Blender:
    """A stand-in runtime: sweeps are point-wise blends, reconstructions the inputs moved by (0.3, 0.4)."""

    def interpolate(self, curves, weights, reading=None):
        a, b = curves
        return SimpleNamespace(curves=[w[0] * a + w[1] * b for w in weights])

    def reconstruct(self, curves, reading=None):
        return SimpleNamespace(curves=[np.asarray(c) + [0.3, 0.4] for c in curves])


def test_run_morphs_measures_each_reading_beside_point_wise_blending_and_tabulates_them():
    pairs = morph_pairs(bspline_curves(6, seed=2), count=3)
    report = run_morphs(Blender(), pairs, steps=5, readings={"one": None, "two": None})
    assert report["pairs"] == 3 and report["steps"] == 5
    for name in ("one", "two"):  # sweeps that are point-wise blends measure as point-wise blending
        r = report[name]
        assert {k: r[k] for k in report["pointwise"]} == pytest.approx(report["pointwise"])
        assert r["ends_rel_rmse_pct"] == pytest.approx(0.0, abs=1e-9)  # the sweeps' ends are the inputs
        diag = [np.hypot(*np.ptp(c, axis=0)) for p in pairs for c in p]
        assert r["reconstruct_rel_rmse_pct"] == pytest.approx(100 * np.mean(0.5 / np.array(diag)))
    table = format_morphs(report).splitlines()
    assert [row.split("|")[1].strip() for row in table[2:]] == ["one", "two", "pointwise"]
    assert table[-1].rstrip().endswith("– | – | – |")  # point-wise blending has no reconstructions to compare
