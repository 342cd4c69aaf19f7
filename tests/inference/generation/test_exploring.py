"""inference/generation/exploring.py: the principal directions of the latent distribution, the grid of offsets, the
latents."""

from __future__ import annotations

import numpy as np

from curve_vae.inference.generation.exploring import grid_offsets, neighbour_latents, principal_directions
from curve_vae.inference.generation.prior import LatentPrior


def _mixture(rng: np.random.Generator, k: int = 3, z: int = 5) -> LatentPrior:
    chol = np.tril(rng.normal(size=(k, z, z))) + 2 * np.eye(z)
    return LatentPrior(np.full(k, 1 / k), rng.normal(scale=4, size=(k, z)), chol)


def test_the_directions_are_the_mixtures_own_as_its_draws_show():
    rng = np.random.default_rng(0)
    prior = _mixture(rng)
    d = principal_directions(prior, 5, 2)
    draws = np.array([prior.draw(rng) for _ in range(40_000)])
    values, vectors = np.linalg.eigh(np.cov(draws.T))
    assert np.allclose(d.deviations, np.sqrt(values[::-1][:2]), rtol=0.03)
    assert abs(d.vectors[0] @ vectors[:, -1]) > 0.99  # the same direction, whichever its sign
    assert np.allclose(d.vectors @ d.vectors.T, np.eye(2), atol=1e-12)
    assert d.deviations[0] >= d.deviations[1] and 0 < d.shares.sum() <= 1


def test_a_direction_keeps_its_sign_whatever_the_order_of_the_components():
    prior = _mixture(np.random.default_rng(1))
    order = [2, 0, 1]
    swapped = LatentPrior(prior.weights[order], prior.means[order], prior.cholesky[order])
    assert np.allclose(principal_directions(prior, 5, 3).vectors, principal_directions(swapped, 5, 3).vectors)


def test_the_standard_prior_moves_along_the_first_axes():
    d = principal_directions(None, 4, 2)
    assert np.array_equal(d.vectors, np.eye(4)[:2]) and np.array_equal(d.deviations, [1, 1])


def test_a_grid_of_offsets_is_row_by_row_and_its_middle_is_the_curve_itself():
    offsets = grid_offsets(3, 2.0, 2)
    assert offsets.tolist()[:4] == [[-2, -2], [-2, 0], [-2, 2], [0, -2]] and len(offsets) == 9
    prior = _mixture(np.random.default_rng(2))
    d = principal_directions(prior, 5, 2)
    z = np.arange(5.0)
    latents = neighbour_latents(z, d, offsets)
    assert np.array_equal(latents[4], z)
    assert np.allclose(latents[5] - z, 2 * d.deviations[1] * d.vectors[1])
