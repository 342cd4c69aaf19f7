"""Curve families beyond the paper's generator: the broad training mix and the held-out evaluation families.

Users post hand-drawn strokes, CAD polylines and airfoil files: shapes the paper's sector-ordered
generator rarely makes, spaced by arc length or unevenly, drawn in any direction. Each family here
draws curves densely along its natural parameter; `respace` then picks the model's points at one of
three spacings, and `to_pose` brings every curve into the pose the service gives posted curves
(geometry.frame.pose_frames) and the model plane's frame — so the model spends its capacity on
shapes, not on orientations it never has to see.

TRAIN_FAMILIES feed training (`DataConfig.mix = "broad"`); HELD_OUT families are never trained on
and measure generalisation in the evaluation suite (training/suite.py).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from types import MappingProxyType
from typing import TypedDict

import numpy as np

from curve_vae.errors import InvalidInput
from curve_vae.geometry import random_control_points, sample_bspline, self_intersects
from curve_vae.geometry.frame import (  # noqa: F401  (MODEL_SIZE: the size these curves are posed at)
    MODEL_SIZE,
    canonical_frame,
    chord_heading,
    cumulative_length,
    posed_frame,
    turns_clockwise,
)

DENSE = 641  # points per curve before respacing: 4× the model's, so every spacing interpolates finely
SPACINGS = ("parameter", "arc_length", "warped")

Family = Callable[[np.random.Generator, int], np.ndarray]  # (rng, count) -> (count, DENSE, 2), any frame


def _u(count: int) -> np.ndarray:
    return np.linspace(0.0, 1.0, DENSE)[None, :].repeat(count, axis=0)


def paper(rng: np.random.Generator, count: int) -> np.ndarray:
    """The paper's curves (§3.1): 10 control points, one per angular sector of a radius-64 circle."""
    return sample_bspline(random_control_points(rng, count), DENSE)


def polygon(rng: np.random.Generator, count: int) -> np.ndarray:
    """Free cubic B-splines: 4–12 control points along a random walk whose heading changes by a random
    amount each step — inflections, winding, S-bends — stretched to an aspect ratio between 1:5 and 1:1."""
    out = np.empty((count, DENSE, 2))
    for i in range(count):
        n = int(rng.integers(4, 13))
        spread = rng.uniform(0.2, 1.6)
        heading = rng.uniform(-np.pi, np.pi) + np.cumsum(rng.normal(0.0, spread, n - 1))
        steps = rng.uniform(0.3, 1.0, n - 1)[:, None] * np.stack([np.cos(heading), np.sin(heading)], 1)
        ctrl = np.concatenate([[[0.0, 0.0]], np.cumsum(steps, axis=0)]) * [1.0, rng.uniform(0.2, 1.0)]
        out[i] = sample_bspline(ctrl[None], DENSE)[0]
    return out


def arc(rng: np.random.Generator, count: int) -> np.ndarray:
    """Arcs of circles and ellipses (axis ratio 0.3–1) sweeping 15°–330°."""
    sweep = rng.uniform(np.radians(15), np.radians(330), (count, 1))
    start = rng.uniform(0, 2 * np.pi, (count, 1))
    t = start + sweep * _u(count)
    ratio = np.where(rng.random((count, 1)) < 0.5, 1.0, rng.uniform(0.3, 1.0, (count, 1)))
    return np.stack([np.cos(t), ratio * np.sin(t)], axis=2)


def spiral(rng: np.random.Generator, count: int) -> np.ndarray:
    """Archimedean and logarithmic spirals of 0.6–2.2 turns, from an inner radius of 5–40% of the outer."""
    turns = rng.uniform(0.6, 2.2, (count, 1)) * 2 * np.pi
    inner = rng.uniform(0.05, 0.4, (count, 1))
    u = _u(count)
    log = rng.random((count, 1)) < 0.5
    r = np.where(log, inner ** (1 - u), inner + (1 - inner) * u)
    t = turns * u
    return np.stack([r * np.cos(t), r * np.sin(t)], axis=2)


def wave(rng: np.random.Generator, count: int) -> np.ndarray:
    """Graphs y = A·sin(2πfx + φ) over 0.25–2.5 periods, A from 0 (a straight line) to 0.6 of the length."""
    u = _u(count)
    f = rng.uniform(0.25, 2.5, (count, 1))
    amp = np.where(rng.random((count, 1)) < 0.1, 0.0, rng.uniform(0.02, 0.6, (count, 1)))
    phase = rng.uniform(0, 2 * np.pi, (count, 1))
    return np.stack([u, amp * np.sin(2 * np.pi * f * u + phase)], axis=2)


def naca(rng: np.random.Generator, count: int) -> np.ndarray:
    """NACA 4-digit airfoils (camber 0–7%, its position 20–60%, thickness 6–20%) from the trailing edge over
    the upper surface and back, cosine-spaced like the coordinate files of real airfoils."""
    beta = np.linspace(0.0, np.pi, (DENSE + 1) // 2)
    x = (1 - np.cos(beta)) / 2
    out = np.empty((count, DENSE, 2))
    for i in range(count):
        m, p, t = rng.uniform(0, 0.07) * (rng.random() < 0.8), rng.uniform(0.2, 0.6), rng.uniform(0.06, 0.2)
        yt = (
            5
            * t
            * (  # open trailing edge: -0.1015 x^4
                0.2969 * np.sqrt(x) - 0.1260 * x - 0.3516 * x**2 + 0.2843 * x**3 - 0.1015 * x**4
            )
        )
        yc = np.where(x < p, m / p**2 * (2 * p * x - x**2), m / (1 - p) ** 2 * (1 - 2 * p + 2 * p * x - x**2))
        upper = np.stack([x, yc + yt], 1)[::-1]
        lower = np.stack([x, yc - yt], 1)[1:]
        out[i] = np.concatenate([upper, lower])
    return out


def closed(rng: np.random.Generator, count: int) -> np.ndarray:
    """Closed outlines: ellipses (a third of them) and blobs r(θ) = 1 + Σ a_k·cos(kθ + φ_k), k = 2–4, stretched to an
    axis ratio of 0.3–1, once round from a random start either way — the loops designers draw, which the open
    families never close. Not in the VAE's mix; the reading ranker learns from them (training/ranker_labels.py)."""
    k = np.arange(2, 5)[None, None, :]
    blob = rng.random((count, 1, 1)) >= 1 / 3
    amp = rng.uniform(0.0, 0.3, (count, 1, 3)) / (k - 1) * blob * (rng.random((count, 1, 3)) < 0.7)
    way = np.where(rng.random((count, 1)) < 0.5, 1.0, -1.0)
    t = rng.uniform(0, 2 * np.pi, (count, 1)) + way * 2 * np.pi * _u(count)
    r = 1.0 + (amp * np.cos(k * t[:, :, None] + rng.uniform(0, 2 * np.pi, (count, 1, 3)))).sum(axis=2)
    ratio = rng.uniform(0.3, 1.0, (count, 1))
    return np.stack([r * np.cos(t), ratio * r * np.sin(t)], axis=2)


# ------------------------------------------------------------------------------------------ held out


def superellipse(rng: np.random.Generator, count: int) -> np.ndarray:
    """Arcs of superellipses |x|^p + |y/b|^p = 1 (p 0.7–4, b 0.4–1), sweeping 60°–300°: corners the training
    families round off."""
    t = rng.uniform(0, 2 * np.pi, (count, 1)) + rng.uniform(np.radians(60), np.radians(300), (count, 1)) * _u(count)
    p = rng.uniform(0.7, 4.0, (count, 1))
    b = rng.uniform(0.4, 1.0, (count, 1))
    c, s = np.cos(t), np.sin(t)
    return np.stack([np.sign(c) * np.abs(c) ** (2 / p), b * np.sign(s) * np.abs(s) ** (2 / p)], axis=2)


def stroke(rng: np.random.Generator, count: int) -> np.ndarray:
    """Hand-drawn-like strokes: a random walk of the heading as a sum of 1–4 low-frequency sines."""
    u = _u(count)
    k = np.arange(1, 5)[None, None, :]
    amp = rng.normal(0, 1, (count, 1, 4)) / k * (rng.random((count, 1, 4)) < 0.7)
    heading = rng.uniform(-np.pi, np.pi, (count, 1)) + (amp * np.sin(np.pi * k * u[:, :, None])).sum(axis=2) * 1.5
    steps = np.stack([np.cos(heading), np.sin(heading)], axis=2) / DENSE
    return np.cumsum(steps, axis=1)


def lissajous(rng: np.random.Generator, count: int) -> np.ndarray:
    """Pieces of Lissajous figures x = sin(a·t + δ), y = sin(b·t), a, b ∈ {1, 2, 3}."""
    a = rng.integers(1, 4, (count, 1))
    b = rng.integers(1, 4, (count, 1))
    t = rng.uniform(0, 2 * np.pi, (count, 1)) + rng.uniform(0.6, 2.5, (count, 1)) * _u(count)
    delta = rng.uniform(0, np.pi, (count, 1))
    return np.stack([np.sin(a * t + delta), np.sin(b * t)], axis=2)


TRAIN_FAMILIES: dict[str, Family] = {
    "paper": paper,
    "polygon": polygon,
    "arc": arc,
    "spiral": spiral,
    "wave": wave,
    "naca": naca,
}
HELD_OUT: dict[str, Family] = {"superellipse": superellipse, "stroke": stroke, "lissajous": lissajous}
#: Families the reading ranker may be labelled on (`curve-vae ranker label --families`): the training families and
#: closed outlines, which the VAE's mix leaves out but users post.
RANKER_FAMILIES: dict[str, Family] = {**TRAIN_FAMILIES, "closed": closed}


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


# ------------------------------------------------------------------------------------------ spacing and pose


def warp(rng: np.random.Generator, count: int, n_points: int, strength: float = 1.0) -> np.ndarray:
    """Random monotone re-parametrisations of [0, 1] (count, n_points): the point density varies up to ~e^±2."""
    u = np.linspace(0.0, 1.0, 257)
    k = np.arange(1, 4)[None, :, None]
    amp = rng.normal(0, 0.7 * strength, (count, 3, 1)) / k
    logd = (amp * np.sin(np.pi * k * u + rng.uniform(0, np.pi, (count, 3, 1)))).sum(1)
    dens = np.exp(logd)
    cdf = np.concatenate([np.zeros((count, 1)), np.cumsum((dens[:, 1:] + dens[:, :-1]) / 2, axis=1)], axis=1)
    cdf /= cdf[:, -1:]
    grid = np.linspace(0.0, 1.0, n_points)
    return np.stack([np.interp(grid, c, u) for c in cdf])


def respace(dense: np.ndarray, n_points: int, spacings: list[str], rng: np.random.Generator) -> np.ndarray:
    """Points (B, n_points, 2) of dense curves (B, DENSE, 2), each at its spacing: evenly in the curve's own
    parameter, evenly by arc length, or at a random monotone warp of the parameter. End points are kept."""
    out = np.empty((len(dense), n_points, 2))
    idx = np.arange(dense.shape[1])
    warps = warp(rng, len(dense), n_points)
    for i, (c, sp) in enumerate(zip(dense, spacings)):
        if sp == "arc_length":
            s = cumulative_length(c)
            x = np.interp(np.linspace(0.0, s[-1], n_points), s, idx)
        elif sp == "warped":
            x = warps[i] * (len(c) - 1)
        else:
            x = np.linspace(0.0, len(c) - 1, n_points)
        out[i] = np.stack([np.interp(x, idx, c[:, 0]), np.interp(x, idx, c[:, 1])], axis=1)
    return out


def to_pose(
    curves: np.ndarray,
    rng: np.random.Generator,
    model_size: float,
    *,
    also: np.ndarray | None = None,
    canonical: bool = False,
) -> np.ndarray:
    """Each curve mirrored to turn counter-clockwise, its chord turned to a random direction between −135° and
    −45° (where the service's pose candidates put it) — or, `canonical`, into geometry.canonical_frame's one
    pose — then shifted and scaled so its bounding box is centred in the model plane with its larger side
    `model_size`, exactly as the service maps a posted curve. `also` (same shape): other samples of the same
    curves, moved in place by each curve's move."""
    out = np.empty_like(curves, dtype=np.float64)
    for i, c in enumerate(np.asarray(curves, np.float64)):
        if canonical:
            frame = canonical_frame(c)
        else:
            mirror = turns_clockwise(c)
            turn = rng.uniform(-0.75 * np.pi, -0.25 * np.pi) - chord_heading(c * [-1.0, 1.0] if mirror else c)
            frame = posed_frame(c, turn, mirror=mirror)
        out[i] = frame.to_model(c, model_size)
        if also is not None:
            also[i] = frame.to_model(np.asarray(also[i], np.float64), model_size)
    return out


def draw_family(
    family: Family,
    count: int,
    rng: np.random.Generator,
    *,
    n_points: int = 161,
    model_size: float | None = MODEL_SIZE,
    spacings: tuple[str, ...] = SPACINGS,
    chunk: int = 1024,
    twins: bool = False,
    canonical: bool = False,
) -> np.ndarray:
    """`count` curves (count, n_points, 2) float32 of one family without self-intersections, each at a spacing
    drawn from `spacings`; in the model's pose and frame, or as drawn for model_size None. twins: (2, count,
    n_points, 2), the curves and the same curves evenly in their own parameter, in the same pose ("twins").
    canonical: each in geometry.canonical_frame's pose (to_pose)."""
    out, pairs, have = [], [], 0
    while have < count:
        dense = family(rng, chunk)
        ok = ~self_intersects(dense[:, ::4])  # 161 of the dense points: the model's resolution
        dense = dense[ok & np.isfinite(dense).all(axis=(1, 2))]
        pts = respace(dense, n_points, list(rng.choice(spacings, len(dense))), rng)
        even = respace(dense, n_points, ["parameter"] * len(dense), rng) if twins else None
        if model_size is not None:
            pts = to_pose(pts, rng, model_size, also=even, canonical=canonical)
        out.append(pts.astype(np.float32))
        if even is not None:
            pairs.append(even.astype(np.float32))
        have += len(pts)
    if twins:
        return np.stack([np.concatenate(out)[:count], np.concatenate(pairs)[:count]])
    return np.concatenate(out)[:count]


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
