"""What the runtime returns: one result object per call, its parts named (curves, latents, frames, splines, errors),
as scipy.optimize returns an OptimizeResult. Arrays are numpy; curves are in the caller's frame unless the call was
in the model's plane (frames None)."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from curve_vae.geometry import Frame, closeness


@dataclass(frozen=True)
class Spline:
    """A returned curve as a clamped cubic B-spline in the caller's frame: the curve's points are the spline at
    `params` exactly (the model's B-spline head; a similarity keeps B-splines)."""

    control_points: np.ndarray  # (n_ctrl, 2)
    knots: np.ndarray  # (n_ctrl + degree + 1,)
    degree: int
    params: np.ndarray  # (n,) parameter of each returned point, in [0, 1]

    def json(self) -> dict[str, Any]:
        return {
            "control_points": self.control_points.tolist(),
            "knots": self.knots.tolist(),
            "degree": self.degree,
            "params": self.params.tolist(),
        }


@dataclass(frozen=True)
class Closeness:
    """How close each answer came to its input, relative to the input's size (geometry.closeness): the RMS and the
    largest distance over the input's points, each ÷ its bounding-box diagonal, and the index of that farthest point.
    Unitless: 0.001 is 0.1% of the curve's diagonal, an airfoil's or a stroke's alike."""

    rms: np.ndarray  # (B,)
    max: np.ndarray  # (B,)
    max_at: np.ndarray  # (B,) int

    @classmethod
    def of(cls, inputs: Sequence[np.ndarray], outputs: Sequence[np.ndarray]) -> Closeness:
        return cls(*closeness(inputs, outputs))

    def part(self, cut: slice) -> Closeness:
        return Closeness(self.rms[cut], self.max[cut], self.max_at[cut])

    def json(self) -> list[dict[str, Any]]:
        """As the API reports it: one {rms, max, max_at} per curve (null where float64 overflowed)."""
        return [
            {"rms": _finite(r), "max": _finite(m), "max_at": int(i)} for r, m, i in zip(self.rms, self.max, self.max_at)
        ]


def _finite(value: Any) -> float | None:
    v = float(value)
    return v if np.isfinite(v) else None


def no_closeness(count: int = 0) -> Closeness:
    return Closeness(np.zeros(count), np.zeros(count), np.zeros(count, np.int64))


@dataclass(frozen=True)
class Encoding:
    """Latent means and log-variances (B, latent_dim) of the curves, and the frame (with its pose) each was mapped
    from (None for frame "model"); with refine, the means are the fitted latents."""

    mean: np.ndarray
    log_var: np.ndarray
    frames: list[Frame | None]
    closeness: Closeness | None = None  # where the reading decoded each latent (closest placement)


def _cuts(sizes: Sequence[int]) -> list[slice]:
    ends = np.cumsum(sizes)
    return [slice(int(e - n), int(e)) for n, e in zip(sizes, ends)]


def split_encoding(enc: Encoding, sizes: Sequence[int]) -> list[Encoding]:
    """`enc` cut into consecutive parts of `sizes` curves (inference.coalescing: each request's own)."""
    return [
        Encoding(enc.mean[c], enc.log_var[c], enc.frames[c], None if enc.closeness is None else enc.closeness.part(c))
        for c in _cuts(sizes)
    ]


def head_splines(splines: Sequence[Spline | None], has_splines: bool) -> list[Spline] | None:
    """A result's splines: each curve's from a model with a B-spline head (which returns one for every curve), None
    from a model without one."""
    return [s for s in splines if s is not None] if has_splines else None


@dataclass(frozen=True)
class Curves:
    """Decoded curves (B, n, 2), the frame each is in (None: the model's plane) and, from a model with a B-spline
    head, each as a spline (None without one)."""

    curves: np.ndarray
    frames: list[Frame | None]
    splines: list[Spline] | None = None


@dataclass(frozen=True)
class Reconstruction:
    """Each curve encoded and decoded, at its own points (curves of different lengths: a list), with its error
    (paper eq. 4 at the input's points, in the caller's frame) and the latent it was decoded from."""

    curves: list[np.ndarray]
    mse: np.ndarray  # (B,)
    latents: np.ndarray  # (B, latent_dim)
    frames: list[Frame | None]
    splines: list[Spline] | None = None
    closeness: Closeness = field(default_factory=no_closeness)  # relative to each input's size
    # (B,) bool: the decoded curve crossed itself where the input does not, and its spline was untangled near the
    # crossing (inference.untangling); its latent decodes to the curve before
    repaired: np.ndarray = field(default_factory=lambda: np.zeros(0, bool))


def split_reconstruction(rec: Reconstruction, sizes: Sequence[int]) -> list[Reconstruction]:
    """`rec` cut into consecutive parts of `sizes` curves (inference.coalescing: each request's own)."""
    return [
        Reconstruction(
            rec.curves[c],
            rec.mse[c],
            rec.latents[c],
            rec.frames[c],
            None if rec.splines is None else rec.splines[c],
            rec.closeness.part(c),
            rec.repaired[c],
        )
        for c in _cuts(sizes)
    ]


@dataclass(frozen=True)
class Interpolation(Curves):
    """Curves decoded from affine mixes of the inputs' latents (paper eqs. 9, 10), one per weight row."""

    weights: np.ndarray = field(default_factory=lambda: np.zeros((0, 0)))  # (rows, inputs)
    valid: np.ndarray = field(default_factory=lambda: np.zeros(0, bool))  # (rows,) free of self-crossings
    repaired: np.ndarray = field(default_factory=lambda: np.zeros(0, bool))  # (rows,) untangled (inference.untangling)
    ends: Closeness = field(default_factory=no_closeness)  # each input's reconstruction in the set's pose, vs the input


@dataclass(frozen=True)
class Sampled(Curves):
    """New curves from a latent distribution: the latents drawn and the bookkeeping of rejection."""

    latents: np.ndarray = field(default_factory=lambda: np.zeros((0, 0)))
    prior: str = "learned"
    seed: int = 0
    offset: int = 0  # index of the first curve in the seeded sequence
    rejected: int = 0  # draws rejected (self-intersecting or outside the reference region) and drawn again
    invalid: int = 0  # curves still not valid after the last draw (0 unless the distribution is far off)


@dataclass(frozen=True)
class Augmented(Curves):
    """Items start … stop-1 of a seeded augmentation sequence: each a mix of its sources (anchor first)."""

    sources: np.ndarray = field(default_factory=lambda: np.zeros((0, 0), np.int64))  # (m, k)
    weights: np.ndarray = field(default_factory=lambda: np.zeros((0, 0)))  # (m, k)
    seed: int = 0
    offset: int = 0
    redrawn: int = 0  # mixes that crossed themselves and were drawn again (their item's own generator)
    invalid: int = 0  # items still crossing themselves after MAX_REDRAWS draws (returned; normally 0)
