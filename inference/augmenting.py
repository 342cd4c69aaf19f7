"""Data augmentation with the VAE (paper §4): seed curves encoded once, new curves mixed between them.

`Augmenting` gives `CurveRuntime` its augment methods (it needs `prepare`, `_encoded`, `_mix` and `batch_size`);
`AugmentPlan` is the seeded rule that draws item i of a sequence, the same whatever the page or chunk size.
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Literal

import numpy as np

from curve_vae.geometry import Frame
from curve_vae.inference.errors import InputError

if TYPE_CHECKING:
    from curve_vae.inference.prepared import Prepared
    from curve_vae.inference.runtime import FrameMode, PoseMode, Spacing, Spline


class Augmenting:
    """The augment methods of CurveRuntime."""

    batch_size: int
    prepare: Any
    _encoded: Any
    _mix: Any

    def plan_augment(
        self,
        curves: Sequence[np.ndarray],
        *,
        mode: AugmentMode = "pair",
        seed: int,
        neighbours: int | None = None,
        frame: FrameMode = "auto",
        spacing: Spacing = "auto",
        pose: PoseMode = "auto",
    ) -> AugmentPlan:
        """Encode the seed curves once and fix who may be mixed with whom; see `AugmentPlan`.

        neighbours: each anchor's partners come from its `neighbours` nearest curves by
        Euclidean distance between latent means (interpolating near neighbours gives better
        curves, paper §4); None: from all the other curves.
        """
        k = SOURCES_PER_MODE[mode]
        if len(curves) < k:
            raise InputError(("curves",), f"mode {mode} needs at least {k} curves, got {len(curves)}")
        if neighbours is not None and neighbours < k - 1:
            raise InputError(
                ("neighbours",), f"mode {mode} mixes each curve with {k - 1} others: at least {k - 1}, got {neighbours}"
            )
        if neighbours is not None and neighbours > len(curves) - 1:
            raise InputError(
                ("neighbours",),
                f"at most {len(curves) - 1} (each curve has {len(curves) - 1} others), got {neighbours}; "
                "omit it to mix any curve with any other",
            )
        prep = self.prepare(curves, frame, spacing, pose)
        mean = self._encoded(prep)[0].astype(np.float64)
        n = len(mean)
        distance = np.linalg.norm(mean[:, None, :] - mean[None, :, :], axis=-1)  # (n, n)
        np.fill_diagonal(distance, np.inf)  # never one's own partner
        m = n - 1 if neighbours is None else neighbours
        pools = np.sort(np.argsort(distance, axis=1, kind="stable")[:, :m], axis=1)
        return AugmentPlan(prep=prep, mean=mean, k=k, seed=seed, pools=pools)

    def augment_batch(
        self,
        plan: AugmentPlan,
        start: int,
        stop: int,
        *,
        n_points: int | None = None,
        spacing: Spacing = "parameter",
        splines: list[Spline] | None = None,
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, list[Frame | None]]:
        """Items start … stop-1 of the plan's sequence: curves, sources (m, k), weights (m, k), frames."""
        sources, weights = plan.draw(start, stop)
        full = np.zeros((len(sources), len(plan.mean)))
        np.put_along_axis(full, sources, weights, axis=1)
        out, frames = self._mix(plan.prep, plan.mean, full, n_points, spacing, splines)
        return out, sources, weights, frames

    def augment_chunks(
        self,
        plan: AugmentPlan,
        start: int,
        stop: int,
        *,
        n_points: int | None = None,
        spacing: Spacing = "parameter",
        chunk: int | None = None,
    ) -> Iterator[np.ndarray]:
        """The curves of items start … stop-1, `chunk` at a time (default batch_size): bounded memory for any count."""
        step = chunk or self.batch_size
        for i in range(start, stop, step):
            yield self.augment_batch(plan, i, min(i + step, stop), n_points=n_points, spacing=spacing)[0]


AugmentMode = Literal["pair", "triplet"]
SOURCES_PER_MODE: dict[str, int] = {"pair": 2, "triplet": 3}


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
