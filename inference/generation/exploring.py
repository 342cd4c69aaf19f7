"""Curves around one curve: its latent moved along the directions the data varies most (the principal directions of
the latent distribution the samples come from), a small grid a designer can pick from.

The learned prior is a Gaussian mixture (inference/generation/prior.py); its covariance as a whole is the weighted
components'
covariances plus the spread of their means, Σ = Σ_k w_k (L_k L_kᵀ + μ_k μ_kᵀ) − μ μᵀ. Its leading eigenvectors are
the directions along which the training curves' latents vary most, and the square roots of their eigenvalues the
standard deviations along them: an offset of 1 is one standard deviation of the data along that direction. Under
the standard prior N(0, I) every direction varies alike; the latent's first axes stand in for them.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from curve_vae.geometry.validity import crosses
from curve_vae.inference.generation.prior import LatentPrior
from curve_vae.inference.results import Spline


@dataclass(frozen=True)
class Directions:
    vectors: np.ndarray  # (k, Z) unit vectors, the data's largest variance first
    deviations: np.ndarray  # (k,) the standard deviation of the distribution along each
    shares: np.ndarray  # (k,) each direction's share of the distribution's total variance


def principal_directions(prior: LatentPrior | None, latent_dim: int, k: int) -> Directions:
    """The k directions of largest variance of `prior` (None: the standard prior N(0, I))."""
    if prior is None:
        return Directions(np.eye(latent_dim)[:k], np.ones(k), np.full(k, 1.0 / latent_dim))
    w, mu, chol = prior.weights, prior.means, prior.cholesky
    mean = w @ mu
    cov = np.einsum("k,kij,klj->il", w, chol, chol) + np.einsum("k,ki,kj->ij", w, mu, mu) - np.outer(mean, mean)
    values, vectors = np.linalg.eigh((cov + cov.T) / 2)  # ascending
    order = np.argsort(values)[::-1][:k]
    values = np.clip(values[order], 0.0, None)
    vectors = vectors[:, order].T
    vectors *= np.where(vectors.sum(axis=1, keepdims=True) < 0, -1.0, 1.0)  # a sign fixed by the data, not LAPACK
    return Directions(vectors, np.sqrt(values), values / max(float(np.trace(cov)), 1e-300))


def grid_offsets(steps: int, spread: float, k: int) -> np.ndarray:
    """(steps**k, k) offsets in standard deviations, each axis evenly from −spread to spread; the last direction
    varies fastest (row-major: for two directions, a row of the grid per offset along the first)."""
    axis = np.linspace(-spread, spread, steps)
    return np.stack(np.meshgrid(*([axis] * k), indexing="ij"), axis=-1).reshape(-1, k)


def neighbour_latents(z: np.ndarray, directions: Directions, offsets: np.ndarray) -> np.ndarray:
    """(rows, Z): the latent z (Z,) moved by each row of offsets (standard deviations along each direction)."""
    return z[None, :] + (offsets * directions.deviations[None, :]) @ directions.vectors


@dataclass(frozen=True)
class Explored:
    """The grid around a curve: its curves (rows, n, 2) in the curve's frame, their splines (a B-spline head's), each
    row's offsets in standard deviations, whether each curve is free of self-crossings, the directions and the
    distribution they are of."""

    curves: np.ndarray
    splines: list[Spline] | None
    offsets: np.ndarray
    valid: np.ndarray
    directions: Directions
    prior: str


def explore(rt: Any, curve: np.ndarray, reading: Any, *, steps: int, spread: float, directions: int,
            prior: str | None, n_points: int | None) -> Explored:  # fmt: skip
    """CurveRuntime.explore's work: the grid around `curve` in its own frame (see there)."""
    chosen = rt.sampler.resolve(prior)
    named = rt.priors.get(chosen)
    mixture = named.mixture if named is not None else (rt.prior if chosen == "learned" else None)
    axes = principal_directions(mixture, rt.latent_dim, directions)
    enc = rt.encode([curve], reading)
    offsets = grid_offsets(steps, spread, directions)
    z = neighbour_latents(enc.mean[0].astype(np.float64), axes, offsets)
    made = rt.decode(z, n_points=n_points or len(curve), frames=[f for f in enc.frames if f] * len(z) or None)
    return Explored(made.curves, made.splines, offsets, ~crosses(list(made.curves)), axes, chosen)
