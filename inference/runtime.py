"""The VAE at inference time: ONNX sessions plus the geometry that brings any curve to them and back.

`CurveRuntime.load(model_dir)` checks the manifest and the sha256 of both graphs, opens
one onnxruntime session per graph on the requested providers and runs a warm-up. Its
methods take and return numpy arrays, so everything the service does can be tested
without HTTP:

    caller's curve (n, 2)  --fit_frame, to_model_plane-->  (161, 2) in the model plane
        --encoder--> mean, log_var --(affine mix)--> decoder --> (161, 2) in the model plane
        --polyline_to_caller / spline_to_caller: n points, same spacing--> caller's frame

With frame "model" the frame steps are skipped. Resampling ("spacing"): "parameter" takes a curve's points as
given and interpolates along the index (the paper's B-spline samples are spaced so); a 161-point curve then passes
untouched and 50, 160 or 500 points of the same curve give the same model input. "natural" reads the curve at even
steps of the parameters of the cubic B-spline fitted to it (the paper's curves' spacing, recovered for most of
them), "arc_length" evenly by arc length (geometry.adapt), and "auto", the default, tries "parameter" and each of
the curve's natural readings (geometry.natural_readings: one or two) and keeps the closest reconstruction, as pose
"auto" does with poses. Nothing here
imports torch. Reading and checking model files is `inference.model_files`; the learned latent
distribution is `inference.prior`.

Length (~500 lines): one class whose methods share the choice of pose (which needs both graphs) and carry a batch's
frames, input positions and splines from `prepare` through the graphs to the result, turning geometry's errors into
the service's InputError with the field and curve they concern. Its parts live beside it: the candidate readings and
the kept batch are `inference.prepared`; the sessions, signature checks and raw graph runs are `inference.graphs` (the
base class `ModelGraphs`); the pure frame and length adaptation is `geometry.adapt`; augmentation
`inference.augmenting`, sampling `inference.sampling` and the fitting of `refine` `inference.fitting` (base classes too);
the input error `inference.errors`; the mixing weights `geometry.mixing`.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, Literal

import numpy as np

from curve_vae.geometry import (
    BeyondFloat32,
    Frame,
    blend_frames,
    closest_squared_distances,
    curve_length,
    fit_frame,
    mse_per_curve,
    natural_params,
    natural_readings,
    polyline_to_caller,
    pose_frames,
    self_intersects,
    smoothness,
    spline_to_caller,
    to_model_plane,
)
from curve_vae.geometry.adapt import F32_MAX, is_closed, joined_ends
from curve_vae.inference.augmenting import Augmenting
from curve_vae.inference.errors import InputError
from curve_vae.inference.fitting import Fitting
from curve_vae.inference.graphs import ModelGraphs
from curve_vae.inference.prepared import Candidates, Prepared
from curve_vae.inference.sampling import Sampling

FrameMode = Literal["auto", "model"]
Spacing = Literal["parameter", "arc_length", "natural", "auto"]
PoseMode = Literal["auto", "as_is"]
#: A natural reading whose parameters are all within this of the points' index fractions reads the curve as given:
#: spacing "auto" does not try it beside "parameter".
SAME_READING = 1e-4
#: Pose candidates a curve is tried in with pose "auto": its chord turned to −90°, −45° and −135°, each as drawn
#: and reversed-and-mirrored (geometry.frame.pose_frames); the reconstruction closest to the input wins.
POSE_CHORD_COUNT = 3
_ENCODE_OVERFLOW = 'encodes to non-finite values: coordinates far outside the model\'s plane (use frame "auto")'


# --------------------------------------------------------------------------- curves in and out


@dataclass(frozen=True)
class Spline:
    """A returned curve as a clamped cubic B-spline in the caller's frame: the curve's points are
    the spline at `params` exactly (the model's B-spline head; a similarity keeps B-splines)."""

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


class CurveRuntime(ModelGraphs, Augmenting, Sampling, Fitting):
    """An exported model's graphs (`ModelGraphs`) with the frame, length and pose handling that brings any curve to
    them and back.

    Methods that return curves take `splines`: a list to which one `Spline` per returned curve
    is appended, for models with a B-spline head (`has_splines`).
    """

    # ----------------------------------------------------------------------- caller's curves

    def prepare(
        self,
        curves: Sequence[np.ndarray],
        frame: FrameMode = "auto",
        spacing: Spacing = "auto",
        pose: PoseMode = "auto",
        refine: int = 0,
        *,
        placed: bool = True,
    ) -> Prepared:
        """Bring caller curves (each (n_i, 2), n_i ≥ 4) to the model's frame and point count.

        pose "auto" (frame "auto" only): each curve is tried in the poses of `geometry.pose_frames` — so a
        curve, its reversal, mirror image and rotations all get the same candidates — encoded and decoded in
        each, and the pose whose reconstruction is closest to the input is kept, with its latent.
        spacing "auto": so are the readings of each curve in each pose, its points as given ("parameter") and at
        even steps of each of their `natural_readings` ("natural"). refine > 0: that many fitting steps on each kept
        latent (`_refined`). A model placed "closest" (its manifest's spline.placement, `closest_placement`) has each
        input point matched to its closest point on its reconstruction even without steps, unless `placed` is False
        (encoding only).
        """
        prep = self._prepare(curves, frame, spacing, pose)
        return self._refined(prep, refine) if refine > 0 or (placed and self.closest_placement) else prep

    def _prepare(self, curves: Sequence[np.ndarray], frame: FrameMode, spacing: Spacing, pose: PoseMode) -> Prepared:
        posing = frame == "auto" and pose == "auto"
        first = "parameter" if spacing == "auto" else spacing
        inputs, poses, naturals = [], [], []
        with np.errstate(all="ignore"):
            for i, c in enumerate(curves):
                pts = np.asarray(c, dtype=np.float64)
                inputs.append(pts)
                try:
                    poses.append(
                        list(pose_frames(pts, chords=POSE_CHORD_COUNT))
                        if posing
                        else [fit_frame(pts) if frame == "auto" else None]
                    )
                    # the natural parameters do not depend on the pose: fitted once; "auto" tries each fit's
                    naturals.append(
                        natural_readings(pts)
                        if spacing == "auto"
                        else [natural_params(pts)]
                        if spacing == "natural"
                        else [None]
                    )
                except ValueError as e:  # all points coincide
                    raise InputError(("curves", i), str(e)) from e
        # every curve in every pose, read as the request says; "auto": its points as given and each natural reading
        # that does not put them where they are (a curve at the paper's own spacing is read so: nothing to add)
        readings = [
            [(first, naturals[i][0])]
            + (
                [("natural", n) for n in naturals[i] if np.abs(n - np.linspace(0.0, 1.0, len(n))).max() > SAME_READING]
                if spacing == "auto"
                else []
            )
            for i in range(len(inputs))
        ]
        stage = [(i, f, r, n) for i in range(len(inputs)) for f in poses[i] for r, n in readings[i]]
        if len(stage) == len(inputs):  # one candidate each: nothing to choose, nothing encoded yet
            with np.errstate(all="ignore"):
                rows = [self._to_model_points(inputs[i], f, r, i, n) for i, f, r, n in stage]
                batch = np.stack([m for m, _ in rows]) if rows else np.zeros((0, self.n_points, 2))
            return Prepared(batch.astype(np.float32), [f for _, f, _, _ in stage], [fr for _, fr in rows], inputs)
        return self._candidates(inputs, stage).closest(inputs)

    def _candidates(
        self, inputs: list[np.ndarray], stage: list[tuple[int, Frame | None, Spacing, np.ndarray | None]]
    ) -> Candidates:
        """Candidate readings (curve index, frame, spacing, natural parameters) encoded, decoded and measured."""
        rows, fractions = [], []
        with np.errstate(all="ignore"):
            for i, f, reading, natural in stage:
                m, fraction = self._to_model_points(inputs[i], f, reading, i, natural)
                rows.append(m)
                fractions.append(fraction)
            batch = np.stack(rows).astype(np.float32) if rows else np.zeros((0, self.n_points, 2), np.float32)
            mean, log_var = self.encode_model(batch)
            _check_finite(mean, "curves", _ENCODE_OVERFLOW)
            _check_finite(log_var, "curves", _ENCODE_OVERFLOW)
            decoded, ctrl, params = self.decode_model_splines(mean)
            if self.closest_placement:  # the points go to their closest points: measured so, to the decoded polyline
                err = np.array([closest_squared_distances(b, d).sum() for b, d in zip(batch, decoded)])
            else:
                err = ((decoded.astype(np.float64) - batch) ** 2).sum(axis=(1, 2))
        return Candidates(
            [i for i, _, _, _ in stage],
            batch,
            [f for _, f, _, _ in stage],
            fractions,
            mean,
            log_var,
            decoded,
            ctrl,
            params,
            err,
        )

    def _to_model_points(
        self, pts: np.ndarray, f: Frame | None, spacing: Spacing, i: int, natural: np.ndarray | None = None
    ) -> tuple[np.ndarray, np.ndarray | None]:
        """One caller curve -> its model-plane points (n_points, 2) and where its own points sit along them."""
        try:
            return to_model_plane(
                pts, f, model_size=self.model_size, n_points=self.n_points, spacing=spacing, natural=natural
            )
        except BeyondFloat32:
            raise InputError(
                ("curves", i),
                "its extent is too small or too large to map to the model's frame"
                if f is not None
                else 'coordinates beyond float32 range; use frame "auto"',
            ) from None

    def _encoded(self, prep: Prepared) -> tuple[np.ndarray, np.ndarray]:
        """Latent means and log-variances of prepared curves (computed once)."""
        if prep.mean is not None and prep.log_var is not None:
            return prep.mean, prep.log_var
        with np.errstate(all="ignore"):
            mean, log_var = self.encode_model(prep.model)
        _check_finite(mean, "curves", _ENCODE_OVERFLOW)
        _check_finite(log_var, "curves", _ENCODE_OVERFLOW)
        return mean, log_var

    def _to_caller(
        self,
        out: np.ndarray,
        frame: Frame | None,
        *,
        n_points: int | None,
        spacing: Spacing = "parameter",
        fractions: np.ndarray | None = None,
        ctrl: np.ndarray | None = None,
        params: np.ndarray | None = None,
        splines: list[Spline] | None = None,
    ) -> np.ndarray:
        """One model-plane result (n_points_model, 2) -> the caller's frame and length (geometry.adapt): n_points
        spaced as `spacing` says, else at the input's positions (`fractions`), else the model's points. With the
        control points of a B-spline head (`ctrl`) the points are the spline's (at the head's learned `params`
        where it has them), and the spline is appended to `splines`."""
        if ctrl is None:
            return polyline_to_caller(
                out, frame, model_size=self.model_size, n_points=n_points, spacing=spacing, fractions=fractions
            )
        curve, c, u = spline_to_caller(
            ctrl,
            frame,
            model_size=self.model_size,
            degree=self.spline_degree,
            model_points=self.n_points,
            n_points=n_points,
            spacing=spacing,
            fractions=fractions,
            model_params=params,
        )
        if splines is not None:
            assert self.knots is not None
            splines.append(Spline(c, self.knots, self.spline_degree, u))
        return curve

    def encode(
        self,
        curves: Sequence[np.ndarray],
        *,
        frame: FrameMode = "auto",
        spacing: Spacing = "auto",
        pose: PoseMode = "auto",
        refine: int = 0,
    ) -> tuple[np.ndarray, np.ndarray, list[Frame | None]]:
        """Latent mean and log-variance of each curve, and the frame (with its pose) each was mapped from; with
        `refine`, the means are the fitted latents (see `prepare`)."""
        prep = self.prepare(curves, frame, spacing, pose, refine, placed=False)
        mean, log_var = self._encoded(prep)
        return mean, log_var, prep.frames

    def decode(
        self,
        latents: np.ndarray,
        *,
        n_points: int | None = None,
        frames: Sequence[Frame] | None = None,
        spacing: Spacing = "parameter",
        splines: list[Spline] | None = None,
    ) -> np.ndarray:
        """Curves (B, n, 2) for latents (B, latent_dim): in the model plane, or mapped to `frames`."""
        z = np.asarray(latents, np.float64)
        if z.ndim != 2 or z.shape[1] != self.latent_dim:
            raise InputError(("latents",), f"expected rows of {self.latent_dim} numbers, got shape {list(z.shape)}")
        _check_range(z, "latents")
        with np.errstate(all="ignore"):
            out, ctrl, params = self.decode_model_splines(z)
        return self._place(out, ctrl, params, frames=frames, n_points=n_points, spacing=spacing, splines=splines)

    def _place(
        self,
        out: np.ndarray,
        ctrl: np.ndarray | None,
        params: np.ndarray | None,
        *,
        frames: Sequence[Frame] | None,
        n_points: int | None,
        spacing: Spacing,
        splines: list[Spline] | None,
    ) -> np.ndarray:
        """Decoded curves (B, n_points_model, 2) (and control points, parameters) -> the caller's frames and length,
        checked."""
        with np.errstate(all="ignore"):
            _check_finite(
                out, "latents", "decodes to non-finite coordinates: the latent is far outside the training range"
            )
            curves = [
                self._to_caller(
                    o,
                    frames[i] if frames else None,
                    n_points=n_points,
                    spacing=spacing,
                    ctrl=None if ctrl is None else ctrl[i],
                    params=None if params is None else params[i],
                    splines=splines,
                )
                for i, o in enumerate(out)
            ]
        result = np.stack(curves) if curves else np.zeros((0, n_points or self.n_points, 2))
        _check_finite(result, "frames" if frames else "latents", "the result does not fit in float64")
        return result

    def reconstruct(
        self,
        curves: Sequence[np.ndarray],
        *,
        frame: FrameMode = "auto",
        n_points: int | None = None,
        spacing: Spacing = "auto",
        splines: list[Spline] | None = None,
        pose: PoseMode = "auto",
        refine: int = 0,
    ) -> tuple[list[np.ndarray], np.ndarray]:
        """Encode the means, decode them; the curves in the caller's frame and their MSE (paper eq. 4) there.

        The MSE compares each input with its reconstruction at the input's own points, whatever `n_points` asks
        for the returned curves. A closed input (its last point its first) comes back closed: the reconstruction's
        ends are joined at their midpoint. With `refine` the latents are fitted first (see `prepare`) and the
        input's own points are matched to their closest points on the reconstruction.
        """
        prep = self.prepare(curves, frame, spacing, pose, refine)
        with np.errstate(all="ignore"):
            if prep.decoded is not None:
                out, ctrl, params = prep.decoded, prep.ctrl, prep.params
            else:
                mean, _ = self._encoded(prep)
                out, ctrl, params = self.decode_model_splines(mean)
            results, mse = [], np.empty(len(out))
            for i, o in enumerate(out):
                c, u = None if ctrl is None else ctrl[i], None if params is None else params[i]
                if is_closed(prep.inputs[i]):  # a loop comes back a loop
                    o, c = _joined(o, c)
                kept = splines if n_points is None else None
                # refined: the spline's points closest to the input's, at their parameters (not the head's)
                at, head = (prep.fractions[i], u) if prep.feet is None else (prep.feet[i], None)
                own = self._to_caller(o, prep.frames[i], n_points=None, fractions=at, ctrl=c, params=head, splines=kept)
                mse[i] = mse_per_curve(prep.inputs[i][None], own[None])[0]
                if n_points is not None:
                    own = self._to_caller(
                        o, prep.frames[i], n_points=n_points, spacing=spacing, ctrl=c, params=u, splines=splines
                    )
                results.append(own)
                if not (np.isfinite(results[-1]).all() and np.isfinite(mse[i])):
                    raise InputError(("curves", i), "the reconstruction does not fit in float64: scale the curve down")
        return results, mse

    def interpolate(
        self,
        curves: Sequence[np.ndarray],
        weights: np.ndarray,
        *,
        frame: FrameMode = "auto",
        n_points: int | None = None,
        spacing: Spacing = "auto",
        splines: list[Spline] | None = None,
        pose: PoseMode = "auto",
        refine: int = 0,
    ) -> tuple[np.ndarray, list[Frame | None]]:
        """Decode affine combinations of the curves' latent means (paper eqs. 9, 10), one per weight row.

        weights: (rows, len(curves)), rows summing to 1. With frame "auto" each interpolant
        comes back in the same blend of the inputs' frames. Length: n_points; else the
        inputs' common length, at the blend of their points' positions; else the model's.
        With `refine` the means are the fitted latents (see `prepare`), and the positions blended are the input
        points' closest points on their fitted splines, so a row of weights [1, 0, …] gives the refined
        reconstruction of the first curve. When every input is closed (`reconstruct`), so is every interpolant.
        """
        prep = self.prepare(curves, frame, spacing, pose, refine)
        mean, _ = self._encoded(prep)
        return self._mix(prep, mean.astype(np.float64), np.asarray(weights, np.float64), n_points, spacing, splines)

    def _mix(
        self,
        prep: Prepared,
        mean: np.ndarray,
        w: np.ndarray,
        n_points: int | None,
        spacing: Spacing,
        splines: list[Spline] | None = None,
    ) -> tuple[np.ndarray, list[Frame | None]]:
        """Decode weight rows w (rows, len(prep.inputs)) over the encoded means; see `interpolate`."""
        auto = prep.frames and prep.frames[0] is not None
        with np.errstate(all="ignore"):
            # Row by row, never a matrix product: BLAS sums in an order that depends on the number of rows, and
            # a curve must not change with the batch or page it is made in.
            z = (w[:, :, None] * mean[None, :, :]).sum(axis=1)  # (rows, latent_dim)
            _check_range(z, "weights")
            out, ctrl, params = self.decode_model_splines(z)
            _check_finite(out, "weights", "the weighted latent decodes to non-finite coordinates: weights too extreme")
            given = [f for f in prep.frames if f is not None]
            frames: list[Frame | None] = (
                [blend_frames(given, w[r : r + 1])[0] for r in range(len(w))] if auto else [None] * len(w)
            )
            common = self._common_length(prep)
            placed = prep.feet is not None or all(f is not None for f in prep.fractions)
            blend = n_points is None and common is not None and placed
            if n_points is None and common is None:
                n_points = self.n_points
            closed = bool(prep.inputs) and all(is_closed(c) for c in prep.inputs)  # loops mix into loops
            results = []
            for r, o in enumerate(out):
                c, u = None if ctrl is None else ctrl[r], None if params is None else params[r]
                if closed:
                    o, c = _joined(o, c)
                if blend:  # refined: blend the spline parameters of the input points (not the head's)
                    at, head = (prep.fractions, u) if prep.feet is None else (prep.feet, None)
                    positions = w[r] @ np.stack(at)  # type: ignore[arg-type]
                    positions = np.maximum.accumulate(np.clip(positions, 0.0, 1.0))  # extrapolating rows stay ordered
                    results.append(
                        self._to_caller(
                            o, frames[r], n_points=None, fractions=positions, ctrl=c, params=head, splines=splines
                        )
                    )
                else:
                    results.append(
                        self._to_caller(
                            o, frames[r], n_points=n_points, spacing=spacing, ctrl=c, params=u, splines=splines
                        )
                    )
            result = np.stack(results) if results else np.zeros((0, self.mix_length(prep, n_points), 2))
        _check_finite(result, "weights", "the interpolant does not fit in float64")
        return result, frames

    @staticmethod
    def _common_length(prep: Prepared) -> int | None:
        lengths = {len(c) for c in prep.inputs}
        return lengths.pop() if len(lengths) == 1 else None

    def mix_length(self, prep: Prepared, n_points: int | None) -> int:
        """Points per curve that mixing `prep`'s curves returns: n_points, else their common length, else 161."""
        return n_points or self._common_length(prep) or self.n_points


def curve_metrics(curves: Sequence[np.ndarray]) -> list[dict[str, Any]]:
    """Per curve, as the API reports it: smoothness (paper §3.4, degrees), self-intersection, length."""
    out = []
    for c in curves:
        with np.errstate(all="ignore"):
            smooth = {name: _number(v) for name, v in smoothness(c).items()}
            length = _number(curve_length(c))
        out.append({"smoothness": smooth, "self_intersects": bool(self_intersects(c)), "length": length})
    return out


def _joined(out: np.ndarray, ctrl: np.ndarray | None) -> tuple[np.ndarray, np.ndarray | None]:
    """A decoded curve (and its control points) closed: the ends joined at their midpoint (geometry.joined_ends), on
    the control points where there are some (a clamped B-spline's end points are its end control points)."""
    return (joined_ends(out), None) if ctrl is None else (out, joined_ends(ctrl))


def _number(value: Any) -> float | None:
    """A JSON number, or null where float64 overflowed (curves near the float limit)."""
    v = float(value)
    return v if math.isfinite(v) else None


def _check_finite(a: np.ndarray, field: str, msg: str) -> None:
    bad = ~np.isfinite(a).reshape(len(a), -1).all(axis=1)
    if bad.any():
        raise InputError((field, int(np.argmax(bad))), msg)


def _check_range(a: np.ndarray, field: str) -> None:
    bad = ~(np.abs(a) <= F32_MAX).reshape(len(a), -1).all(axis=1)
    if bad.any():
        raise InputError((field, int(np.argmax(bad))), "values beyond float32 range")
