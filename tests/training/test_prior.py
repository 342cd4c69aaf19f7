"""training/prior.py: the latent priors. A full-covariance mixture fitted by EM, its size chosen by BIC; manifold
Parzen windows, one component per latent along its neighbours' directions; a user's curves read in the canonical pose
into a named prior."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from curve_vae.errors import InvalidInput
from curve_vae.training.prior import fit_by_bic, fit_named_prior, fit_parzen, fit_prior, prior_reading
from tests.helpers import bspline_curves


def _clusters(n: int = 120, seed: int = 0) -> np.ndarray:
    """Two tight clusters in 3 dimensions, 10 apart."""
    rng = np.random.default_rng(seed)
    return np.concatenate([rng.normal(0, 0.1, (n, 3)), rng.normal(0, 0.1, (n, 3)) + [10.0, 0.0, 0.0]])


def test_parzen_windows_are_one_component_per_latent_spread_as_its_neighbours():
    z = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 2.0], [5.0, 5.0]])
    prior = fit_parzen(z, neighbours=2, scale=0.5)
    np.testing.assert_array_equal(prior.means, z)
    np.testing.assert_allclose(prior.weights, [0.25] * 4)
    # (0, 0)'s two nearest are (1, 0) and (0, 2): differences (1, 0), (0, 2); their mean outer product is
    # diag(1, 4) / 2, times 0.5², plus 1e-6·I
    cov = prior.cholesky[0] @ prior.cholesky[0].T
    np.testing.assert_allclose(cov, np.diag([0.5, 2.0]) * 0.25 + 1e-6 * np.eye(2), atol=1e-12)
    far = prior.cholesky[3] @ prior.cholesky[3].T  # (5, 5)'s nearest: (1, 0) (41 away²) then (0, 2) (34): both
    d = np.array([[1.0, 0.0], [0.0, 2.0]]) - [5.0, 5.0]
    np.testing.assert_allclose(far, d.T @ d / 2 * 0.25 + 1e-6 * np.eye(2), atol=1e-12)


def test_parzen_with_fewer_latents_than_neighbours_uses_every_other_one():
    prior = fit_parzen(np.array([[0.0, 0.0], [2.0, 0.0]]), neighbours=5, scale=1.0)
    np.testing.assert_allclose(prior.cholesky[0] @ prior.cholesky[0].T, [[4 + 1e-6, 0], [0, 1e-6]], atol=1e-12)


def test_em_finds_two_clusters_weights_and_means():
    prior = fit_prior(_clusters(), components=2)
    order = np.argsort(prior.means[:, 0])
    np.testing.assert_allclose(prior.weights[order], [0.5, 0.5], atol=1e-6)
    np.testing.assert_allclose(prior.means[order], [[0, 0, 0], [10, 0, 0]], atol=0.05)
    cov = prior.cholesky @ np.swapaxes(prior.cholesky, 1, 2)
    np.testing.assert_allclose(np.diagonal(cov, axis1=1, axis2=2), 0.01 + 1e-4, rtol=0.4)  # 0.1², plus reg_covar


def test_bic_chooses_the_two_clusters_and_tries_at_most_one_component_per_20_latents():
    prior, bic = fit_by_bic(_clusters(), max_components=5)
    assert list(bic) == [1, 2, 3, 4, 5] and min(bic, key=bic.__getitem__) == 2 and len(prior.weights) == 2
    _, few = fit_by_bic(_clusters(n=30))  # 60 latents: counts 1 to 3
    assert list(few) == [1, 2, 3]
    given, tried = fit_by_bic(_clusters(), components=4)
    assert list(tried) == [4] and len(given.weights) == 4


@pytest.mark.parametrize(
    "model,spacing",
    [
        pytest.param(SimpleNamespace(frame="auto", spacing="search"), "parameter", id="search-read-as-given"),
        pytest.param(SimpleNamespace(frame="model", spacing="arc_length"), "arc_length", id="models-own-spacing"),
    ],
)
def test_a_priors_curves_are_read_in_the_canonical_pose(model, spacing):
    reading = prior_reading(model, refine=3)
    assert (reading.frame, reading.pose, reading.spacing, reading.refine) == (model.frame, "canonical", spacing, 3)


def test_a_named_prior_of_a_users_curves_holds_their_latents_and_says_how_it_was_made(runtime):
    curves = list(bspline_curves(5, 90, seed=3))
    prior = fit_named_prior(runtime, curves, name="mine", refine=0, source="my folder")
    assert prior.name == "mine" and len(prior.mixture.weights) == 5 and prior.reference.latents.shape == (5, 32)
    meta = prior.meta
    assert meta["kind"] == "parzen" and meta["source"] == "my folder" and meta["reading"]["pose"] == "canonical"
    assert meta["model_name"] == runtime.manifest.name and meta["model_version"] == runtime.manifest.version
    with pytest.raises(InvalidInput, match="kind must be parzen or gmm, got 'kde'"):
        fit_named_prior(runtime, curves, name="mine", kind="kde", refine=0)
