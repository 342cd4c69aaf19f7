"""The learned latent distribution: a Gaussian mixture fitted to the latent means of training curves.

A VAE's prior N(0, I) is where its KL term pulls the latents, not where the data's latents
are: with β = 1e-3 in pixel units the shipped encoder's means spread 4–12 per dimension, so
z ~ N(0, I) decodes to small tangles no data curve maps to. Sampling this mixture instead
generates curves from where the data lives (`curve-vae export` fits it, training/prior.py).

Stored as `prior.npz` beside the graphs (weights (K,), means (K, Z), cholesky (K, Z, Z): the
lower Cholesky factor of each component's covariance), listed in the manifest with its sha256.
`temperature` scales every component's spread about its mean: 1 is the fitted density,
0 gives the component means, as it gives the origin for the standard prior.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from curve_vae.errors import InvalidInput
from curve_vae.files import atomic_path

PRIOR_FILE = "prior.npz"


@dataclass(frozen=True)
class LatentPrior:
    weights: np.ndarray  # (K,) mixing weights, summing to 1
    means: np.ndarray  # (K, Z)
    cholesky: np.ndarray  # (K, Z, Z) lower factors: covariance_k = L_k L_kᵀ

    def __post_init__(self) -> None:
        k, z = self.means.shape
        if self.weights.shape != (k,) or self.cholesky.shape != (k, z, z):
            raise InvalidInput(
                f"prior shapes disagree: weights {self.weights.shape}, means {self.means.shape}, "
                f"cholesky {self.cholesky.shape}"
            )
        if not (np.isfinite(self.means).all() and np.isfinite(self.cholesky).all() and np.all(self.weights >= 0)):
            raise InvalidInput("prior parameters must be finite, with non-negative weights")
        if not np.isclose(self.weights.sum(), 1.0, atol=1e-6):
            raise InvalidInput(f"prior weights sum to {self.weights.sum()}, not 1")

    @property
    def latent_dim(self) -> int:
        return int(self.means.shape[1])

    def draw(self, rng: np.random.Generator, temperature: float = 1.0) -> np.ndarray:
        """One latent (Z,) from the mixture, its spread scaled by `temperature`; consumes rng in a fixed pattern."""
        k = int(rng.choice(len(self.weights), p=self.weights))
        eps = rng.standard_normal(self.latent_dim)
        return self.means[k] + temperature * (self.cholesky[k] @ eps)

    def save(self, path: str | Path) -> None:
        """Write atomically (a temporary file renamed over `path`)."""
        with atomic_path(path) as tmp, open(tmp, "wb") as f:
            np.savez(f, weights=self.weights, means=self.means, cholesky=self.cholesky)

    @classmethod
    def load(cls, path: str | Path) -> LatentPrior:
        with np.load(path, allow_pickle=False) as z:
            return cls(
                weights=np.asarray(z["weights"], np.float64),
                means=np.asarray(z["means"], np.float64),
                cholesky=np.asarray(z["cholesky"], np.float64),
            )
