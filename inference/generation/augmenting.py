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
from curve_vae.inference.generation.mixing import mix
from curve_vae.inference.results import Augmented, Interpolation

if TYPE_CHECKING:
    from curve_vae.inference.model.graphs import ModelGraphs
    from curve_vae.inference.prepared import Prepared

#: Draws of one item at most: a mix that crosses itself is drawn again (as /sample redraws), up to this many times.
MAX_REDRAWS = 10


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
        return self.draw_items(np.arange(start, stop), attempt=0)

    def draw_items(self, items: np.ndarray, *, attempt: int) -> tuple[np.ndarray, np.ndarray]:
        """Sources and weights of the given items at their `attempt`-th draw: the first from default_rng([seed, i]),
        a redraw of a mix that crossed itself from default_rng([seed, i, attempt]) (still the item's alone)."""
        sources = np.empty((len(items), self.k), np.int64)
        weights = np.empty((len(items), self.k))
        for row, i in enumerate(items):
            rng = np.random.default_rng([self.seed, int(i)] + ([attempt] if attempt else []))
            anchor = int(rng.integers(len(self.pools)))
            sources[row, 0] = anchor
            sources[row, 1:] = rng.choice(self.pools[anchor], size=self.k - 1, replace=False)
            weights[row] = rng.dirichlet(np.ones(self.k))
        return sources, weights


def augmented(
    g: ModelGraphs, plan: AugmentPlan, start: int, stop: int, *, n_points: int | None, spacing: str, length: int
) -> Augmented:
    """Items start … stop-1 of the plan's sequence, each a valid curve: a mix that crosses itself (after
    inference.placing) is drawn again from its item's own generator, up to MAX_REDRAWS draws; one still crossing
    then is returned and counted `invalid`."""
    sources, weights = plan.draw(start, stop)
    made = _mixed(g, plan, sources, weights, n_points=n_points, spacing=spacing, length=length)
    curves, frames, valid = made.curves.copy(), list(made.frames), made.valid.copy()
    splines = None if made.splines is None else list(made.splines)
    redrawn = 0
    for attempt in range(1, MAX_REDRAWS):
        bad = np.flatnonzero(~valid)
        if not len(bad):
            break
        redrawn += len(bad)
        sources[bad], weights[bad] = plan.draw_items(start + bad, attempt=attempt)
        again = _mixed(g, plan, sources[bad], weights[bad], n_points=n_points, spacing=spacing, length=length)
        curves[bad], valid[bad] = again.curves, again.valid
        for j, b in enumerate(bad):
            frames[b] = again.frames[j]
            if splines is not None and again.splines is not None:
                splines[b] = again.splines[j]
    return Augmented(
        curves,
        frames,
        splines,
        sources=sources,
        weights=weights,
        seed=plan.seed,
        offset=start,
        redrawn=redrawn,
        invalid=int((~valid).sum()),
    )


def _mixed(
    g: ModelGraphs,
    plan: AugmentPlan,
    sources: np.ndarray,
    weights: np.ndarray,
    *,
    n_points: int | None,
    spacing: str,
    length: int,
) -> Interpolation:
    full = np.zeros((len(sources), len(plan.mean)))
    np.put_along_axis(full, sources, weights, axis=1)
    return mix(g, plan.prep, full, n_points=n_points, spacing=spacing, length=length)
