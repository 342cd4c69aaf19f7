"""Curve families beyond the paper's generator, and how their curves are spaced and posed.

Users post hand-drawn strokes, CAD polylines and airfoil files: shapes the paper's sector-ordered
generator rarely makes, spaced by arc length or unevenly, drawn in any direction. Each family here
draws curves densely along its natural parameter; `respace` then picks the model's points at one of
three spacings, and `to_pose` brings every curve into the pose the service gives posted curves
(geometry.frame.pose_frames) and the model plane's frame — so the model spends its capacity on
shapes, not on orientations it never has to see.

TRAIN_FAMILIES feed training (the broad mix, training/mixes.py); HELD_OUT families are never trained on
and measure generalisation in the evaluation suite (training/suite.py); RANKER_FAMILIES are what the
reading ranker may be labelled on (training/ranker_labels.py).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

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
