"""What the runtime returns: one result object per call, its parts named (curves, latents, frames, splines, errors),
as scipy.optimize returns an OptimizeResult. Arrays are numpy; curves are in the caller's frame unless the call was
in the model's plane (frames None).

Each result's JSON body is built here too, as its shape in inference.answers, shared by the REST routes and the
offline CLI: `curve-vae encode|reconstruct|sample|augment|fit` write exactly what POST /encode, /reconstruct, /sample,
/augment and /fit answer for the same request. Arrays stay numpy (the service's orjson writes them directly; the CLI's
JSON writer turns them into lists).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, TypeVar

import numpy as np

from curve_vae.geometry import (
    Frame,
    closeness,
    curve_length,
    fit_bspline,
    fit_bspline_auto,
    self_intersects,
    smoothness,
)
from curve_vae.inference import answers as a
from curve_vae.inference.errors import InputError

if TYPE_CHECKING:  # exploring's results are built of this module's Spline
    from curve_vae.inference.generation.exploring import Explored


@dataclass(frozen=True)
class Spline:
    """A returned curve as a clamped cubic B-spline in the caller's frame: the curve's points are the spline at
    `params` exactly (the model's B-spline head; a similarity keeps B-splines)."""

    control_points: np.ndarray  # (n_ctrl, 2)
    knots: np.ndarray  # (n_ctrl + degree + 1,)
    degree: int
    params: np.ndarray  # (n,) parameter of each returned point, in [0, 1]

    def json(self) -> a.SplineOut:
        return a.SplineOut(
            control_points=self.control_points.tolist(),
            knots=self.knots.tolist(),
            degree=self.degree,
            params=self.params.tolist(),
        )


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

    def json(self) -> list[a.ClosenessOut]:
        """As the API reports it: one {rms, max, max_at} per curve (null where float64 overflowed)."""
        return [
            a.ClosenessOut(rms=_finite(r), max=_finite(m), max_at=int(i))
            for r, m, i in zip(self.rms, self.max, self.max_at)
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
    """`enc` cut into consecutive parts of `sizes` curves (service.deps: each request's own)."""
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
    # crossing (inference.placing); its latent decodes to the curve before
    repaired: np.ndarray = field(default_factory=lambda: np.zeros(0, bool))


def split_reconstruction(rec: Reconstruction, sizes: Sequence[int]) -> list[Reconstruction]:
    """`rec` cut into consecutive parts of `sizes` curves (service.deps: each request's own)."""
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
    repaired: np.ndarray = field(default_factory=lambda: np.zeros(0, bool))  # (rows,) untangled (inference.placing)
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


# The JSON bodies (their shapes: inference.answers).

Body = TypeVar("Body", bound=a.CurvesResponse)  # a body of curves: /decode's, /reconstruct's, /interpolate's, …


def frames_json(frames: Sequence[Frame | None]) -> list[a.FrameOut] | None:
    """Frames as the API reports them; None for frame "model"."""
    if not frames or frames[0] is None:
        return None
    return [
        a.FrameOut(center=f.center, size=f.size, rotation=f.rotation, mirror=f.mirror, reverse=f.reverse)
        for f in frames
        if f is not None
    ]


def with_curves(
    body: Body,
    curves: Sequence[np.ndarray] | np.ndarray,
    splines: Sequence[Spline] | None,
    *,
    metrics: bool = False,
    output: str = "points",
) -> Body:
    """`body` with the per-curve quality measures when the request asked for them (`curves` a list of (n, 2) arrays
    or one (n_curves, n, 2) array), and its curves as the request's `output` asks: "points" (`curves`), "bspline"
    (`splines`) or "both"."""
    if metrics:
        body["metrics"] = curve_metrics(curves)
    if output == "points" or splines is None:
        return body
    body["splines"] = [sp.json() for sp in splines]
    if output == "bspline":
        del body["curves"]
    return body


def encode_body(enc: Encoding) -> a.EncodeResponse:
    # float64 as the JSON always carried: orjson would write float32 at float32's shorter precision
    body = a.EncodeResponse(
        mean=enc.mean.astype(np.float64), log_var=enc.log_var.astype(np.float64), frames=frames_json(enc.frames)
    )
    if enc.closeness is not None:  # the reading decoded each latent (closest placement): how close it came
        body["closeness"] = enc.closeness.json()
    return body


def decode_body(made: Curves, *, metrics: bool = False, output: str = "points") -> a.CurvesResponse:
    body = a.CurvesResponse(curves=made.curves.tolist())
    return with_curves(body, made.curves, made.splines, metrics=metrics, output=output)


def reconstruct_body(rec: Reconstruction, *, metrics: bool = False, output: str = "points") -> a.ReconstructResponse:
    body = a.ReconstructResponse(
        curves=[np.ascontiguousarray(c) for c in rec.curves],
        mse=rec.mse,
        closeness=rec.closeness.json(),
        repaired=rec.repaired.tolist(),
    )
    return with_curves(body, rec.curves, rec.splines, metrics=metrics, output=output)


def interpolate_body(mix: Interpolation, *, metrics: bool = False, output: str = "points") -> a.InterpolateResponse:
    body = a.InterpolateResponse(
        weights=mix.weights,
        curves=np.ascontiguousarray(mix.curves),
        frames=frames_json(mix.frames),
        valid=mix.valid.tolist(),
        repaired=mix.repaired.tolist(),
        ends=mix.ends.json(),
    )
    return with_curves(body, mix.curves, mix.splines, metrics=metrics, output=output)


def sample_body(made: Sampled, *, metrics: bool = False, output: str = "points") -> a.SampleResponse:
    body = a.SampleResponse(
        latents=made.latents.tolist(),
        curves=made.curves.tolist(),
        seed=made.seed,
        offset=made.offset,
        prior=made.prior,
        rejected=made.rejected,
        invalid=made.invalid,
    )
    if made.prior not in ("learned", "standard"):
        # a prior of users' curves places each curve in the frame of its nearest reference curve: say which
        body["frames"] = frames_json(made.frames)
    return with_curves(body, made.curves, made.splines, metrics=metrics, output=output)


def augment_body(made: Augmented, *, metrics: bool = False, output: str = "points") -> a.AugmentResponse:
    body = a.AugmentResponse(
        curves=made.curves.tolist(),
        sources=made.sources.tolist(),
        weights=made.weights.tolist(),
        frames=frames_json(made.frames),
        seed=made.seed,
        offset=made.offset,
        redrawn=made.redrawn,
        invalid=made.invalid,
    )
    return with_curves(body, made.curves, made.splines, metrics=metrics, output=output)


def fit_body(
    curves: Sequence[np.ndarray],
    n_ctrl: int | None = None,
    *,
    param: str = "chord",
    n_points: int | None = None,
    tolerance: float = 1e-3,
) -> a.FitResponse:
    """Least-squares cubic B-spline of each curve (geometry.fit_bspline; without n_ctrl, fit_bspline_auto picks the
    fewest control points within `tolerance` of the diagonal); InputError names a curve it cannot fit."""
    fits = []
    for i, c in enumerate(curves):
        if n_ctrl is not None and len(c) < n_ctrl:
            raise InputError(
                ("curves", i),
                f"n_ctrl={n_ctrl} control points need at least as many points, got {len(c)}; "
                "omit n_ctrl to have it chosen",
            )
        try:
            with np.errstate(all="ignore"):
                f = (
                    fit_bspline(c, n_ctrl, param=param)
                    if n_ctrl is not None
                    else fit_bspline_auto(c, tolerance=tolerance, param=param)
                )
        except (ValueError, np.linalg.LinAlgError) as e:
            raise InputError(("curves", i), _unfittable(n_ctrl, e)) from e
        if not (np.isfinite(f.control_points).all() and np.isfinite([f.rms_error, f.max_error]).all()):
            raise InputError(("curves", i), _unfittable(len(f.control_points)))
        out = a.BSplineOut(
            control_points=f.control_points.tolist(),
            knots=f.knots.tolist(),
            degree=f.degree,
            n_ctrl=len(f.control_points),
            rms_error=f.rms_error,
            max_error=f.max_error,
        )
        if n_points is not None:
            out["curve"] = f.evaluate(n_points).tolist()
        fits.append(out)
    return a.FitResponse(fits=fits)


def _unfittable(n_ctrl: int | None, error: Exception | None = None) -> str:
    why = f" ({error})" if error is not None and len(str(error)) < 120 else ""
    count = f"{n_ctrl}" if n_ctrl is not None else "any number of"
    return (
        f"no unique least-squares spline with {count} control points{why}: some knot span holds too few of the "
        'curve\'s points; use fewer control points, more points, or param "uniform"'
    )


def mesh_file(mesh: Any, *, points: int, segments: int, axis: str, fmt: str) -> bytes:
    """A surface of revolution as the file /revolve answers and `curve-vae revolve` writes: binary STL, or OBJ text
    that says what it is."""
    if fmt == "stl":
        with np.errstate(all="ignore"):  # normals of huge triangles: STL readers recompute them
            return mesh.to_stl()
    comment = f"curve-vae surface of revolution: {points}-point profile, {segments} segments about the {axis} axis"
    return mesh.to_obj(comment=comment).encode()


def curve_metrics(curves: Sequence[np.ndarray] | np.ndarray) -> list[a.CurveMetrics]:
    """Per curve (a list of (n, 2) arrays or one (n_curves, n, 2) array), as the API reports it: smoothness (paper
    §3.4, degrees), self-intersection, length."""
    out = []
    for c in curves:
        with np.errstate(all="ignore"):
            turns = smoothness(c)
            smooth = a.Smoothness(
                mean_turn=_number(turns["mean_turn"]),
                max_turn=_number(turns["max_turn"]),
                roughness=_number(turns["roughness"]),
            )
            length = _number(curve_length(c))
        out.append(a.CurveMetrics(smoothness=smooth, self_intersects=bool(self_intersects(c)), length=length))
    return out


def _number(value: Any) -> float | None:
    """A JSON number, or null where float64 overflowed (curves near the float limit)."""
    v = float(value)
    return v if math.isfinite(v) else None


def explore_body(made: Explored, *, metrics: bool = False, output: str = "points") -> a.ExploreResponse:
    d = made.directions
    body = a.ExploreResponse(
        curves=made.curves.tolist(),
        offsets=made.offsets.tolist(),
        valid=made.valid.tolist(),
        directions=[a.DirectionOut(deviation=float(v), share=float(s)) for v, s in zip(d.deviations, d.shares)],
        prior=made.prior,
    )
    return with_curves(body, made.curves, made.splines, metrics=metrics, output=output)
