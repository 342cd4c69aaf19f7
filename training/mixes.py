"""The broad training mix, by version, and a user's own curves as a data set: what `DataConfig.mix = "broad"` and
`source` draw (training/data.py), from the families of training/families.py, spaced and posed as the service
reads posted curves."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from types import MappingProxyType
from typing import TypedDict

import numpy as np

from curve_vae.errors import InvalidInput
from curve_vae.geometry.frame import MODEL_SIZE
from curve_vae.training.families import DENSE, SPACINGS, TRAIN_FAMILIES, draw_family, paper, respace, to_pose


@dataclass(frozen=True)
class MixSpec:
    """One version of the broad mix: each training family's share, and how the paper's share is drawn."""

    shares: Mapping[str, float]  # family -> share of the mix; the paper's curves stay the largest single share
    paper_raw: float  # of the paper's share: drawn as the paper draws them (its pose, frame, parameter spacing)
    paper_spacings: tuple[str, ...]  # the rest, posed, each respaced at one of these drawn at random
    # "service": chords turned at random between −135° and −45°, where pose_frames' candidates put them (to_pose);
    # "canonical": every curve, the raw share too, in the one pose geometry.canonical_frame reads it in
    pose: str = "service"

    def __post_init__(self) -> None:  # a read-only copy: a version, once made, draws the same curves for good
        object.__setattr__(self, "shares", MappingProxyType(dict(self.shares)))


#: Every broad mix still made, by version (part of a data set's configuration, so a cache made by another
#: version is never read as this one; a model's manifest names the version it was trained on). Version 1 (model
#: 0.8.0: the paper's curves 30%, half as drawn; polygons 30%, the rest 10% each) is no longer made.
MIXES = {
    # model 0.9.0's. Arc length weighs most among the posed paper curves: posted points are rarely spaced by a
    # B-spline parameter, and the paper's curves at arc-length spacing were the suite's hardest set (0.8.0).
    2: MixSpec(
        {"paper": 0.45, "polygon": 0.25, "arc": 0.075, "spiral": 0.075, "wave": 0.075, "naca": 0.075},
        paper_raw=1 / 3,
        paper_spacings=("arc_length", "arc_length", "parameter", "warped"),
    ),
    # model 0.10.0's: the paper's curves at arc-length spacing were still 1.8× the error of the same curves at
    # parameter spacing (0.9.0), so they go from 15% of the mix to 26%; the raw third shrinks to a fifth.
    3: MixSpec(
        {"paper": 0.55, "polygon": 0.21, "arc": 0.06, "spiral": 0.06, "wave": 0.06, "naca": 0.06},
        paper_raw=0.2,
        paper_spacings=("arc_length", "arc_length", "arc_length", "parameter", "warped"),
    ),
    # version 3's curves, each in the one pose the service reads it in (geometry.canonical_frame), so an encoder
    # spends nothing on poses it is never shown; the raw fifth keeps the paper's parameter spacing
    4: MixSpec(
        {"paper": 0.55, "polygon": 0.21, "arc": 0.06, "spiral": 0.06, "wave": 0.06, "naca": 0.06},
        paper_raw=0.2,
        paper_spacings=("arc_length", "arc_length", "arc_length", "parameter", "warped"),
        pose="canonical",
    ),
}
#: The version new data sets are drawn at.
MIX_VERSION = 3
#: The broad mix is drawn in chunks of this many curves, each seeded by (seed, chunk index): the same data for a
#: seed however many processes draw it.
CHUNK = 8192


def own_curves(
    source: str, n_train: int, seed: int, *, n_points: int = 161, model_size: float = MODEL_SIZE, held: float = 0.1
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A user's curves as a data set (train, val, test), each (k, n_points, 2) float32 in the model's pose and frame.

    The curves of `source` (curve_vae.curvefiles.read_curve_files) are split by curve — `held` of them for
    validation, as many for test (at least one each), seeded — so no test curve is trained on. The training
    split is drawn n_train times, each draw in a fresh random pose (to_pose) and at a spacing drawn from
    SPACINGS ("parameter" keeps the file's own spacing, as the service takes posted points by default), so a
    few hundred curves make a data set of any size. Validation and test curves keep their own spacing.
    """
    from curve_vae.curvefiles import read_curve_files
    from curve_vae.geometry import resample

    curves = read_curve_files(source)
    if len(curves) < 3:
        raise InvalidInput(f"{source}: {len(curves)} curves; a data set needs at least 3 (train, validation, test)")
    rng = np.random.default_rng(seed)
    # each curve densely along its own points (its own spacing), and at n_points that way
    dense = np.stack([resample(np.asarray(c, np.float64), DENSE, spacing="parameter") for c in curves])
    own = dense[:, np.round(np.linspace(0, DENSE - 1, n_points)).astype(int)]
    order = rng.permutation(len(dense))
    k = max(1, int(round(held * len(dense))))
    test, val, train = own[order[:k]], own[order[k : 2 * k]], order[2 * k :]
    if not len(train):
        raise InvalidInput(f"{source}: {len(curves)} curves leave none for training after validation and test")
    picked = dense[train[rng.integers(0, len(train), n_train)]]
    drawn = respace(picked, n_points, list(rng.choice(SPACINGS, n_train)), rng)
    return tuple(to_pose(s, rng, model_size).astype(np.float32) for s in (drawn, val, test))  # type: ignore[return-value]


class _Posed(TypedDict):
    """The keywords of `draw_family` that a chunk of the broad mix gives each family alike."""

    n_points: int
    model_size: float
    twins: bool
    canonical: bool


def _mix_chunk(args: tuple[int, int, int, int, float, int, bool]) -> np.ndarray:
    """Chunk `index` of the broad mix of `version`: `count` curves in its shares, drawn with its own seed
    (seed, index); with twins (2, count, n_points, 2), each curve and its twin (`draw_family`)."""
    seed, index, count, n_points, model_size, version, twins = args
    spec = MIXES[version]
    rng = np.random.default_rng([seed, index])
    sizes = {name: int(count * share) for name, share in spec.shares.items()}
    sizes["paper"] += count - sum(sizes.values())  # the rounding's few curves: exactly `count` in all
    canonical = spec.pose == "canonical"
    posed: _Posed = {"n_points": n_points, "model_size": model_size, "twins": twins, "canonical": canonical}
    parts = []
    for name, k in sizes.items():
        if name == "paper":
            raw = int(round(k * spec.paper_raw))
            # evenly in their parameter: their own twins; in the paper's own pose and frame, or the canonical one
            drawn = draw_family(paper, raw, rng, n_points=n_points, model_size=None, spacings=("parameter",))
            if canonical:
                drawn = to_pose(drawn, rng, model_size, canonical=True).astype(np.float32)
            parts.append(np.stack([drawn, drawn]) if twins else drawn)
            parts.append(draw_family(paper, k - raw, rng, spacings=spec.paper_spacings, **posed))
        else:
            parts.append(draw_family(TRAIN_FAMILIES[name], k, rng, **posed))
    return np.concatenate(parts, axis=1 if twins else 0)


def broad_mix(
    count: int,
    seed: int,
    *,
    n_points: int = 161,
    model_size: float = MODEL_SIZE,
    workers: int = 1,
    version: int = MIX_VERSION,
    twins: bool = False,
) -> np.ndarray:
    """`count` curves of the training mix of `version` (MIXES: its shares, shuffled), seeded. Part of the
    paper's share keeps its own pose, frame and parameter spacing (paper_raw), so the model stays as good on
    the paper's curves. Drawn in CHUNK-curve chunks by `workers` processes; the result does not depend on
    `workers`. twins: (2, count, n_points, 2), the curves and their twins (`draw_family`), in the same order; the
    curves are not those drawn without twins (the twins are drawn too)."""
    if version not in MIXES:
        raise InvalidInput(f"the broad mix of version {version} is no longer made (made: {sorted(MIXES)})")
    jobs = [
        (seed, i, min(CHUNK, count - start), n_points, model_size, version, twins)
        for i, start in enumerate(range(0, count, CHUNK))
    ]
    if workers > 1 and len(jobs) > 1:
        import multiprocessing
        from concurrent.futures import ProcessPoolExecutor

        # spawn, not fork: the caller may hold torch's thread pools, which a forked child inherits broken
        with ProcessPoolExecutor(min(workers, len(jobs)), mp_context=multiprocessing.get_context("spawn")) as pool:
            chunks = list(pool.map(_mix_chunk, jobs))
    else:
        chunks = [_mix_chunk(job) for job in jobs]
    if twins:
        pairs = np.concatenate(chunks, axis=1)[:, :count] if chunks else np.empty((2, 0, n_points, 2), np.float32)
        return pairs[:, np.random.default_rng(seed).permutation(pairs.shape[1])]
    curves = np.concatenate(chunks)[:count] if chunks else np.empty((0, n_points, 2), np.float32)
    return curves[np.random.default_rng(seed).permutation(len(curves))]
