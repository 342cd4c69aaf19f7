"""training/suite.py: the evaluation suite of curve families. Its sets are the paper's curves moved and respaced and
each family's, its measures relative RMSE over the input's own points, roughness and crossing, its table a row a set."""

from types import SimpleNamespace

import numpy as np
import pytest

from curve_vae.geometry import resample
from curve_vae.training import families as F
from curve_vae.training.suite import format_suite, measure, random_moves, relative_rmse, run_suite, suite_sets


class Shifted:
    """A stand-in runtime whose reconstructions are the inputs moved by `offset`."""

    def __init__(self, offset=(0.0, 0.0)):
        self.offset = np.asarray(offset, np.float64)

    def reconstruct(self, curves, reading=None):
        return SimpleNamespace(curves=[np.asarray(c, np.float64) + self.offset for c in curves])


def test_suite_bookkeeping_with_a_perfect_reconstructor():
    test = F.draw_family(F.paper, 12, np.random.default_rng(0), model_size=None)
    sets = suite_sets(test, 6)
    report = run_suite(Shifted(), sets)  # returns the input: every error is 0
    assert set(report) == set(sets) and len(sets) >= 10
    assert {r["kind"] for r in report.values()} >= {"paper", "trained", "held out"}
    for r in report.values():
        assert r["n_curves"] == 6
        assert r["rel_rmse_mean"] == 0 and r["roughness_ratio"] == pytest.approx(1)
    assert "paper, rotated" in format_suite(report)


def test_relative_rmse_is_rmse_over_the_diagonal():
    a = np.array([[0.0, 0.0], [3.0, 4.0]])
    assert relative_rmse([a], [a + [0.5, 0.0]])[0] == pytest.approx(0.5 / 5)


def test_a_reconstruction_moved_by_a_constant_is_that_distance_over_the_diagonal():
    square = np.array([[0.0, 0.0], [6.0, 0.0], [6.0, 8.0], [0.0, 8.0]])  # an open U, diagonal 10
    wave = np.stack([np.linspace(0, 30, 50), 4 * np.sin(np.linspace(0, 3, 50))], 1)
    row = measure(Shifted((3.0, 4.0)), [square, wave])  # every point 5 away
    diag = np.array([10.0, np.hypot(30.0, np.ptp(wave[:, 1]))])
    assert row["n_curves"] == 2
    assert row["rel_rmse_mean"] == pytest.approx(np.mean(5 / diag)) and row["rel_rmse_max"] == pytest.approx(0.5)
    assert row["roughness_ratio"] == pytest.approx(1.0)  # a translation turns nothing
    assert row["self_intersecting"] == row["self_intersecting_input"] == 0.0


def test_random_moves_are_seeded_similarities_of_each_curve():
    rng = np.random.default_rng(0)
    curves = [np.cumsum(rng.normal(size=(20, 2)), axis=0) for _ in range(8)]
    a, b = random_moves(curves, np.random.default_rng(4)), random_moves(curves, np.random.default_rng(4))
    assert all(np.array_equal(x, y) for x, y in zip(a, b))
    for before, after in zip(curves, a):
        # turned, mirrored or reversed: the distances between any two points stay, whichever way the curve runs
        d0 = np.linalg.norm(before[:, None] - before[None], axis=-1)
        d1 = np.linalg.norm(after[:, None] - after[None], axis=-1)
        assert np.allclose(d1, d0) or np.allclose(d1, d0[::-1, ::-1])
    assert any(not np.allclose(x, c) for x, c in zip(a, curves))


def test_the_paper_sets_are_the_test_curves_moved_and_respaced(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)  # no data/ here: no airfoil set
    test = F.draw_family(F.paper, 5, np.random.default_rng(1), model_size=None).astype(np.float64)
    sets = suite_sets(test, 4)
    assert "airfoils (UIUC)" not in sets and all(len(curves) == 4 for _, curves in sets.values())
    paper = sets["paper"][1]
    np.testing.assert_array_equal(np.stack(paper), test[:4])
    np.testing.assert_array_equal(np.stack(sets["paper, reversed"][1]), test[:4, ::-1])
    np.testing.assert_array_equal(np.stack(sets["paper, mirrored"][1]), test[:4] * [-1.0, 1.0])
    for c, r in zip(paper, sets["paper, arc-length spacing"][1]):
        np.testing.assert_allclose(r, resample(c, len(c)))
    for c, r in zip(paper, sets["paper, rotated"][1]):  # a rotation about the origin keeps every point's distance
        np.testing.assert_allclose(np.linalg.norm(r, axis=1), np.linalg.norm(c, axis=1))
    kinds = {name: kind for name, (kind, _) in sets.items()}
    assert {kinds[n] for n in F.HELD_OUT} == {"held out"}
    assert {kinds[n] for n in F.TRAIN_FAMILIES if n != "paper"} == {"trained"}


def test_the_table_has_a_row_per_set_in_percent():
    report = {
        "one": {"kind": "paper", "rel_rmse_mean": 0.0125, "rel_rmse_p95": 0.02, "rel_rmse_max": 0.5,
                "roughness_ratio": 1.5, "self_intersecting": 0.25, "self_intersecting_input": 0.0},
        "two": {"kind": "held out", "rel_rmse_mean": 0.1, "rel_rmse_p95": 0.2, "rel_rmse_max": 0.3,
                "roughness_ratio": 2.0, "self_intersecting": 0.0},
    }  # fmt: skip
    lines = format_suite(report).splitlines()
    assert len(lines) == 3 and lines[0].startswith("set")
    assert lines[1].split() == ["one", "paper", "1.25%", "2.00%", "50.00%", "1.50", "0.0%/", "25.0%"]
    assert lines[2].split()[:2] == ["two", "held"] and "10.00%" in lines[2]
