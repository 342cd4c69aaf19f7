"""evaluation.generation: each metric on sets whose answer is known — identical sets, shifted sets, a set and its
copy, a linear decoder."""

from __future__ import annotations

import numpy as np
import pytest

from curve_vae.evaluation import generation as g
from tests.helpers import bspline_curves


@pytest.fixture(scope="module")
def sets() -> tuple[np.ndarray, np.ndarray]:
    a = bspline_curves(120, 40, seed=1) / 64  # two draws of one distribution, about unit size
    b = bspline_curves(120, 40, seed=2) / 64
    return a, b


def test_a_set_against_itself(sets):
    a, _ = sets
    assert g.mmd_ideallab(a, a) == pytest.approx(0, abs=1e-12) and g.mmd_gaussian(a, a) == pytest.approx(0, abs=1e-12)
    assert g.prdc(a, a) == {
        "precision": 1.0,
        "recall": 1.0,
        "density": pytest.approx(g.prdc(a, a)["density"]),
        "coverage": 1.0,
    }
    assert (
        g.coverage(a, a) == 1.0 and g.rvod(a, a) == pytest.approx(1.0) and g.diversity_ratio(a, a) == pytest.approx(1)
    )
    assert g.novelty(a, a) == 0.0 and g.copy_rate(a, a) == 1.0  # a copy of the data is all copies


def test_moving_a_set_away_shows_in_every_distance(sets):
    a, b = sets
    near, far = g.mmd_ideallab(a, b), g.mmd_ideallab(a + 2.0, b)
    assert 0 < near < far and g.mmd_gaussian(a, b) < g.mmd_gaussian(a + 2.0, b)
    assert g.prdc(a + 2.0, b)["precision"] == 0.0 and g.coverage(a + 2.0, b) == 0.0
    assert g.novelty(a + 2.0, b) > g.novelty(a, b) and g.copy_rate(a + 2.0, b) == 0.0
    assert g.rvod(a + 2.0, b) == pytest.approx(g.rvod(a, b))  # a shift keeps every curve's smoothness
    assert g.diversity_ratio(a * 2, a) == pytest.approx(4.0)  # variance scales with the square


def test_diversity_counts_distinct_shapes():
    one = np.repeat(bspline_curves(1, 40)[None, 0], 50, axis=0) / 64
    many = bspline_curves(50, 40, seed=3) / 64
    assert g.vendi(one, sigma=1.0) == pytest.approx(1.0, abs=1e-6) and g.vendi(many) > 5
    assert g.dpp_diversity(one, sigma=1.0) < 1e-3 < g.dpp_diversity(many)


def test_smoothness_ratio_sees_jitter():
    a = bspline_curves(30, 60, seed=4)
    rough = a + np.random.default_rng(0).normal(0, 2.0, a.shape)
    assert g.rvod(rough, a) < 0.9 < g.rvod(a, a) == pytest.approx(1.0)


def test_lsc_is_one_for_a_linear_decoder_and_low_for_noise():
    basis = np.random.default_rng(1).normal(size=(4, 20, 2))
    linear = lambda z: np.einsum("bk,knd->bnd", z, basis)  # noqa: E731
    box = (np.zeros(4), np.ones(4))
    assert g.lsc(linear, box, np.random.default_rng(0), lines=20) == pytest.approx(1.0)
    noise = lambda z: np.random.default_rng(len(z)).normal(size=(len(z), 20, 2))  # noqa: E731
    assert g.lsc(noise, box, np.random.default_rng(0), lines=20) < 0.5


def test_the_interval_is_the_ideallab_one():
    mean, pm = g.interval([1.0, 2.0, 3.0, 4.0])
    assert mean == 2.5 and pm == pytest.approx(1.96 * np.std([1, 2, 3, 4]) / 2)


def test_the_density_of_samples_scores_held_out_shapes(sets):
    pytest.importorskip("sklearn")
    a, b = sets
    assert g.mean_log_likelihood(a, b) > g.mean_log_likelihood(a + 2.0, b)
