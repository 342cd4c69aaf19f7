"""Data augmentation with the VAE (paper §4): seed curves encoded once, new curves mixed between them.

`AugmentPlan` is the seeded rule that draws item i of a sequence, the same whatever the page or chunk size;
`neighbour_pools` fixes who may be mixed with whom. `CurveRuntime.plan_augment` and `.augment` use them.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from curve_vae.inference.choices import SOURCES_PER_MODE
from curve_vae.inference.errors import InputError

if TYPE_CHECKING:
    from curve_vae.inference.prepared import Prepared


def neighbour_pools(mean: np.ndarray, mode: str, neighbours: int | None) -> np.ndarray:
    """(n, m) the curves each seed curve may be mixed with, ascending: every other curve, or its `neighbours`
    nearest by Euclidean distance between latent means (interpolating near neighbours gives better curves, paper
    §4). InputError when the mode needs more curves than there are, or `neighbours` cannot be met."""
    k = SOURCES_PER_MODE[mode]
    n = len(mean)
    if n < k:
        raise InputError(("curves",), f"mode {mode} needs at least {k} curves, got {n}")
    if neighbours is not None and neighbours < k - 1:
        raise InputError(
            ("neighbours",), f"mode {mode} mixes each curve with {k - 1} others: at least {k - 1}, got {neighbours}"
        )
    if neighbours is not None and neighbours > n - 1:
        raise InputError(
            ("neighbours",),
            f"at most {n - 1} (each curve has {n - 1} others), got {neighbours}; omit it to mix any curve with any "
            "other, or send more seed curves",
        )
    distance = np.linalg.norm(mean[:, None, :] - mean[None, :, :], axis=-1)  # (n, n)
    np.fill_diagonal(distance, np.inf)  # never one's own partner
    m = n - 1 if neighbours is None else neighbours
    return np.sort(np.argsort(distance, axis=1, kind="stable")[:, :m], axis=1)


@dataclass(frozen=True)
class AugmentPlan:
    """Seed curves encoded once, and the rule that draws item i of a seeded augmentation sequence.

    Item i depends on (seed, i) alone, through its own generator default_rng([seed, i]): a
    page or chunk of the sequence is the same whatever the page size, and the items can be
    made in any order. Each item: an anchor curve, uniform; its k-1 partners, distinct and
    uniform over the anchor's pool; weights from the flat Dirichlet, i.e. uniform on the
    simplex (each ≥ 0, summing to 1), in the order of the sources.
    """

    prep: Prepared  # the seed curves brought to the model
    mean: np.ndarray  # (n_curves, latent_dim) latent means, float64
    k: int  # sources per new curve: 2 (pair) or 3 (triplet)
    seed: int
    pools: np.ndarray  # (n_curves, m) the curves each anchor may be mixed with, ascending

    def draw(self, start: int, stop: int) -> tuple[np.ndarray, np.ndarray]:
        """Sources (m, k) (anchor first) and weights (m, k) of items start … stop-1."""
        sources = np.empty((stop - start, self.k), np.int64)
        weights = np.empty((stop - start, self.k))
        for row, i in enumerate(range(start, stop)):
            rng = np.random.default_rng([self.seed, i])
            anchor = int(rng.integers(len(self.pools)))
            sources[row, 0] = anchor
            sources[row, 1:] = rng.choice(self.pools[anchor], size=self.k - 1, replace=False)
            weights[row] = rng.dirichlet(np.ones(self.k))
        return sources, weights
