"""The VAE at inference time: ONNX sessions plus the geometry that brings any curve to them and back.

`CurveRuntime.load(model_dir)` checks the manifest and the sha256 of both graphs, opens
one onnxruntime session per graph on the requested providers and runs a warm-up. Its
methods take and return numpy arrays, so everything the service does can be tested
without HTTP:

    caller's curve (n, 2)  --fit_frame, to_model_plane-->  (161, 2) in the model plane
        --encoder--> mean, log_var --(affine mix)--> decoder --> (161, 2) in the model plane
        --polyline_to_caller / spline_to_caller: n points, same spacing--> caller's frame

With frame "model" the frame steps are skipped. Resampling ("spacing"): by default a curve's
points are taken as given and interpolated along the index ("parameter": the paper's B-spline
samples are spaced so, and the default model was also trained at arc-length and uneven spacings);
a 161-point curve then passes untouched and 50, 160 or 500 points of the same curve give the same
model input. "arc_length" resamples evenly by arc length instead (geometry.adapt). Nothing here
imports torch. Reading and checking model files is `service.model_files`; the learned latent
distribution is `service.prior`.

Length (~690 lines): one class whose methods share the sessions and the choice of pose (which needs both
graphs), and carry a batch's frames, input positions and splines from `prepare` through the graphs to the
result, turning geometry's errors into the service's InputError with the field and curve they concern. The
pure frame and length adaptation (caller's frame -> model plane at the model's point count, and back as
points or as a spline) is `geometry.adapt`; augmentation is `service.augmenting` (a base class of
CurveRuntime), the input error `service.inputs`, the mixing weights `geometry.mixing`.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Literal

import numpy as np
import onnxruntime as ort

from curve_vae.geometry import (
    BeyondFloat32,
    Frame,
    blend_frames,
    clamped_uniform_knots,
    curve_length,
    fit_frame,
    mse_per_curve,
    polyline_to_caller,
    pose_frames,
    self_intersects,
    smoothness,
    spline_to_caller,
    to_model_plane,
)
from curve_vae.geometry.adapt import F32_MAX
from curve_vae.geometry.frame import MODEL_CENTER
from curve_vae.service import batching
from curve_vae.service.augmenting import Augmenting
from curve_vae.service.inputs import InputError
from curve_vae.service.model_files import ModelLoadError, graph_file, read_manifest, resolve_providers
from curve_vae.service.prior import PRIOR_FILE, LatentPrior
from curve_vae.service.sessions import SessionConfig, SessionPool, open_pair

log = logging.getLogger(__name__)

FrameMode = Literal["auto", "model"]
Spacing = Literal["parameter", "arc_length"]
PoseMode = Literal["auto", "as_is"]
#: Pose candidates a curve is tried in with pose "auto": its chord turned to −90°, −45° and −135°, each as drawn
#: and reversed-and-mirrored (geometry.frame.pose_frames); the reconstruction closest to the input wins.
POSE_CHORD_COUNT = 3
_ENCODE_OVERFLOW = 'encodes to non-finite values: coordinates far outside the model\'s plane (use frame "auto")'


Prior = Literal["learned", "standard"]
MAX_DRAWS = 10  # per sampled curve: the shipped prior rejects 25% of draws, so 10 fail with probability ~1e-6;
# and a distribution that rejects almost everything (the standard prior) costs at most 10 decodes a curve


@dataclass(frozen=True)
class Sampled:
    """What `CurveRuntime.sample` made: latents (count, Z), curves, the prior used and the bookkeeping of rejection."""

    latents: np.ndarray
    curves: np.ndarray
    prior: str
    rejected: int  # draws rejected (self-intersecting or outside the disc) and drawn again
    invalid: int  # curves still not valid after max_draws (0 unless the distribution is far off)


# --------------------------------------------------------------------------- curves in and out


@dataclass(frozen=True)
class Prepared:
    """A batch of caller curves brought to the model, and what it takes to bring results back."""

    model: np.ndarray  # (B, n_points, 2) float32 in the model plane
    frames: list[Frame | None]  # the caller's frame of each curve; None for frame "model"
    fractions: list[
        np.ndarray | None
    ]  # where each input point sits along the model's points, in [0, 1]; None: same points
    inputs: list[np.ndarray]  # the caller's curves, float64
    # With pose "auto", the curves are already encoded and decoded (that is how the pose is chosen):
    mean: np.ndarray | None = None  # (B, latent_dim)
    log_var: np.ndarray | None = None
    decoded: np.ndarray | None = None  # (B, n_points, 2) model plane
    ctrl: np.ndarray | None = None  # (B, n_ctrl, 2) with a B-spline head


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


class CurveRuntime(Augmenting):
    """Encoder and decoder sessions of one exported model, with frame and length handling.

    Methods that return curves take `splines`: a list to which one `Spline` per returned curve
    is appended, for models with a B-spline head (`has_splines`).
    """

    def __init__(
        self,
        encoder: ort.InferenceSession,
        decoder: ort.InferenceSession,
        manifest: dict[str, Any],
        *,
        batch_size: int = 64,
        requested_providers: str = "cpu",
        prior: LatentPrior | None = None,
        pool: SessionPool | None = None,
    ) -> None:
        self.pool = pool or SessionPool([(encoder, decoder)])  # the pair of each inference thread
        self.manifest = manifest
        self.prior = prior
        self.batch_size = batch_size
        self.requested_providers = requested_providers
        self.n_points = int(manifest["n_points"])
        self.latent_dim = int(manifest["latent_dim"])
        self.model_size = float(manifest["frame"]["model_size"])
        spline = manifest.get("spline")
        self.spline_degree = int(spline["degree"]) if spline else 0
        self.knots = clamped_uniform_knots(int(spline["n_ctrl"]), self.spline_degree) if spline else None
        # Where the data lives in the model plane (paper §3.1: a radius-64 disc in the 128×128 plane): the region a
        # valid sample must stay in.
        self.disc_center = np.asarray(manifest["frame"].get("center", list(MODEL_CENTER)), np.float64)
        self.disc_radius = float(manifest.get("training", {}).get("data", {}).get("radius", 64.0))
        self._enc_in = encoder.get_inputs()[0].name
        self._dec_in = decoder.get_inputs()[0].name
        self._check_signature()

    @classmethod
    def load(
        cls,
        model_dir: str | Path,
        *,
        providers: str = "auto",
        intra_op_threads: int = 0,
        batch_size: int = 64,
        warm_up: bool = True,
        sessions: SessionConfig | None = None,
    ) -> CurveRuntime:
        """Open a model directory; raises ModelLoadError with what to fix when it cannot serve.

        `sessions` sets threads, spinning and the number of session pairs (service.sessions); without it, one pair
        of `intra_op_threads` threads."""
        root = Path(model_dir)
        manifest = read_manifest(root)
        provider_list = resolve_providers(providers)
        config = sessions or SessionConfig(intra_op_threads=intra_op_threads)
        paths = (root / graph_file(manifest, "encoder"), root / graph_file(manifest, "decoder"))
        pool = SessionPool(
            [open_pair(paths, provider_list, config, require_cuda=providers == "cuda") for _ in range(config.sessions)]
        )
        prior = None
        if manifest.get("prior"):
            path = root / str(manifest["prior"].get("file", PRIOR_FILE))
            try:
                prior = LatentPrior.load(path)
            except (OSError, ValueError, KeyError) as e:
                raise ModelLoadError(f"{path}: not a usable latent prior ({e})") from e
        runtime = cls(
            *pool.pairs[0], manifest, batch_size=batch_size, requested_providers=providers, prior=prior, pool=pool
        )
        if warm_up:
            runtime.warm_up()
        return runtime

    def _check_signature(self) -> None:
        enc_in, dec_in = self.encoder.get_inputs()[0], self.decoder.get_inputs()[0]
        enc_out = {o.name for o in self.encoder.get_outputs()}
        problems = []
        if list(enc_in.shape[1:]) != [self.n_points, 2]:
            problems.append(
                f"encoder input {enc_in.name} has shape {enc_in.shape}, expected [batch, {self.n_points}, 2]"
            )
        if not {"mean", "log_var"} <= enc_out:
            problems.append(f"encoder outputs {sorted(enc_out)}, expected mean and log_var")
        if list(dec_in.shape[1:]) != [self.latent_dim]:
            problems.append(
                f"decoder input {dec_in.name} has shape {dec_in.shape}, expected [batch, {self.latent_dim}]"
            )
        dec_out = [o.name for o in self.decoder.get_outputs()]
        if self.has_splines and dec_out[:2] != ["curves", "control_points"]:
            problems.append(f"decoder outputs {dec_out}, expected curves and control_points (the manifest's spline)")
        if self.prior is not None and self.prior.latent_dim != self.latent_dim:
            problems.append(f"the prior has {self.prior.latent_dim} latent dimensions, the model {self.latent_dim}")
        if problems:
            raise ModelLoadError("graphs do not match the manifest: " + "; ".join(problems))

    @property
    def encoder(self) -> ort.InferenceSession:
        """The calling thread's encoder session."""
        return self.pool.pair()[0]

    @property
    def decoder(self) -> ort.InferenceSession:
        """The calling thread's decoder session."""
        return self.pool.pair()[1]

    @property
    def has_splines(self) -> bool:
        """Whether the decoder ends in a B-spline head (curves can be returned as splines)."""
        return self.knots is not None

    @property
    def providers(self) -> list[str]:
        """Providers the sessions actually run on (a fallback shows here)."""
        return list(self.encoder.get_providers())

    def warm_up(self) -> None:
        """One full encode → decode round trip; raises ModelLoadError if the graphs misbehave."""
        t = np.linspace(0.0, np.pi, self.n_points)
        circle = np.stack([64 + 40 * np.cos(t), 64 + 40 * np.sin(t)], axis=1)[None].astype(np.float32)
        try:
            mean, log_var = self.encode_model(circle)
            out = self.decode_model(mean)
        except Exception as e:
            raise ModelLoadError(f"warm-up inference failed: {e}") from e
        if mean.shape != (1, self.latent_dim) or out.shape != (1, self.n_points, 2):
            raise ModelLoadError(f"warm-up gave shapes {mean.shape}, {out.shape}")
        if not (np.isfinite(mean).all() and np.isfinite(log_var).all() and np.isfinite(out).all()):
            raise ModelLoadError("warm-up inference gave non-finite numbers: the weights are broken")
        for encoder, decoder in self.pool.pairs:  # every pair's first run allocates; not a request's
            decoder.run(None, {self._dec_in: encoder.run(["mean"], {self._enc_in: circle})[0]})

    # ----------------------------------------------------------------------- raw graphs

    def encode_model(self, curves: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(B, n_points, 2) in the model plane -> mean, log_var (B, latent_dim); split into runs of batch_size."""
        x = np.ascontiguousarray(curves, dtype=np.float32)
        encoder = self.encoder
        means, log_vars = [], []
        for i in range(0, len(x), self.batch_size):
            mean, log_var = self._run_graph(encoder, "encoder", x[i : i + self.batch_size], ["mean", "log_var"])
            means.append(mean)
            log_vars.append(log_var)
        if not means:
            return np.zeros((0, self.latent_dim), np.float32), np.zeros((0, self.latent_dim), np.float32)
        return np.concatenate(means), np.concatenate(log_vars)

    def _run_graph(
        self, session: ort.InferenceSession, graph: str, x: np.ndarray, outputs: list[str] | None
    ) -> list[np.ndarray]:
        """One run of a graph: gathered with other requests' by the thread's micro-batcher, if it has one."""
        batcher = batching.current()
        if batcher is not None:
            return batcher.run(graph, x, outputs)
        return session.run(outputs, {self._enc_in if graph == "encoder" else self._dec_in: x})

    def decode_model(self, latents: np.ndarray) -> np.ndarray:
        """(B, latent_dim) -> (B, n_points, 2) in the model plane."""
        return self.decode_model_splines(latents)[0]

    def decode_model_splines(self, latents: np.ndarray) -> tuple[np.ndarray, np.ndarray | None]:
        """(B, latent_dim) -> curves (B, n_points, 2) and, with a B-spline head, control points (B, n_ctrl, 2)."""
        z = np.ascontiguousarray(latents, dtype=np.float32)
        decoder = self.decoder
        curves, ctrls = [], []
        for i in range(0, len(z), self.batch_size):
            out = self._run_graph(decoder, "decoder", z[i : i + self.batch_size], None)
            curves.append(out[0])
            ctrls.append(out[1] if self.has_splines else None)
        if not curves:
            n_ctrl = len(self.knots) - self.spline_degree - 1 if self.has_splines else 0
            return np.zeros((0, self.n_points, 2), np.float32), np.zeros((0, n_ctrl, 2), np.float32)
        return np.concatenate(curves), (np.concatenate(ctrls) if self.has_splines else None)

    # ----------------------------------------------------------------------- caller's curves

    def prepare(
        self,
        curves: Sequence[np.ndarray],
        frame: FrameMode = "auto",
        spacing: Spacing = "parameter",
        pose: PoseMode = "auto",
    ) -> Prepared:
        """Bring caller curves (each (n_i, 2), n_i ≥ 4) to the model's frame and point count.

        pose "auto" (frame "auto" only): each curve is tried in the poses of `geometry.pose_frames` — so a
        curve, its reversal, mirror image and rotations all get the same candidates — encoded and decoded in
        each, and the pose whose reconstruction is closest to the input is kept, with its latent.
        """
        posing = frame == "auto" and pose == "auto"
        rows, frames, fractions, inputs = [], [], [], []
        with np.errstate(all="ignore"):
            for i, c in enumerate(curves):
                pts = np.asarray(c, dtype=np.float64)
                inputs.append(pts)
                try:
                    candidates: list[Frame | None] = (
                        list(pose_frames(pts, chords=POSE_CHORD_COUNT))
                        if posing
                        else [fit_frame(pts) if frame == "auto" else None]
                    )
                except ValueError as e:  # all points coincide
                    raise InputError(("curves", i), str(e)) from e
                for f in candidates:
                    m, fraction = self._to_model_points(pts, f, spacing, i)
                    rows.append(m)
                    frames.append(f)
                    fractions.append(fraction)
        batch = np.stack(rows).astype(np.float32) if rows else np.zeros((0, self.n_points, 2), np.float32)
        if not posing:
            return Prepared(batch, frames, fractions, inputs)
        with np.errstate(all="ignore"):
            mean, log_var = self.encode_model(batch)
            _check_finite(mean, "curves", _ENCODE_OVERFLOW)
            _check_finite(log_var, "curves", _ENCODE_OVERFLOW)
            decoded, ctrl = self.decode_model_splines(mean)
            err = ((decoded.astype(np.float64) - batch) ** 2).sum(axis=(1, 2))
        k = len(batch) // max(len(inputs), 1)  # every curve has the same number of candidates, in a row
        best = list(np.arange(len(inputs)) * k + err.reshape(len(inputs), k).argmin(axis=1))
        return Prepared(
            batch[best],
            [frames[b] for b in best],
            [fractions[b] for b in best],
            inputs,
            mean[best],
            log_var[best],
            decoded[best],
            None if ctrl is None else ctrl[best],
        )

    def _to_model_points(
        self, pts: np.ndarray, f: Frame | None, spacing: Spacing, i: int
    ) -> tuple[np.ndarray, np.ndarray | None]:
        """One caller curve -> its model-plane points (n_points, 2) and where its own points sit along them."""
        try:
            return to_model_plane(pts, f, model_size=self.model_size, n_points=self.n_points, spacing=spacing)
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
        splines: list[Spline] | None = None,
    ) -> np.ndarray:
        """One model-plane result (n_points_model, 2) -> the caller's frame and length (geometry.adapt): n_points
        spaced as `spacing` says, else at the input's positions (`fractions`), else the model's points. With the
        control points of a B-spline head (`ctrl`) the points are the spline's, and the spline is appended to
        `splines`."""
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
        spacing: Spacing = "parameter",
        pose: PoseMode = "auto",
    ) -> tuple[np.ndarray, np.ndarray, list[Frame | None]]:
        """Latent mean and log-variance of each curve, and the frame (with its pose) each was mapped from."""
        prep = self.prepare(curves, frame, spacing, pose)
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
            out, ctrl = self.decode_model_splines(z)
        return self._place(out, ctrl, frames=frames, n_points=n_points, spacing=spacing, splines=splines)

    def _place(
        self,
        out: np.ndarray,
        ctrl: np.ndarray | None,
        *,
        frames: Sequence[Frame] | None,
        n_points: int | None,
        spacing: Spacing,
        splines: list[Spline] | None,
    ) -> np.ndarray:
        """Decoded curves (B, n_points_model, 2) (and control points) -> the caller's frames and length, checked."""
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
        spacing: Spacing = "parameter",
        splines: list[Spline] | None = None,
        pose: PoseMode = "auto",
    ) -> tuple[list[np.ndarray], np.ndarray]:
        """Encode the means, decode them; the curves in the caller's frame and their MSE (paper eq. 4) there.

        The MSE compares each input with its reconstruction at the input's own points,
        whatever `n_points` asks for the returned curves.
        """
        prep = self.prepare(curves, frame, spacing, pose)
        with np.errstate(all="ignore"):
            if prep.decoded is not None:
                out, ctrl = prep.decoded, prep.ctrl
            else:
                mean, _ = self._encoded(prep)
                out, ctrl = self.decode_model_splines(mean)
            results, mse = [], np.empty(len(out))
            for i, o in enumerate(out):
                c = None if ctrl is None else ctrl[i]
                kept = splines if n_points is None else None
                own = self._to_caller(
                    o, prep.frames[i], n_points=None, fractions=prep.fractions[i], ctrl=c, splines=kept
                )
                mse[i] = mse_per_curve(prep.inputs[i][None], own[None])[0]
                if n_points is not None:
                    own = self._to_caller(
                        o, prep.frames[i], n_points=n_points, spacing=spacing, ctrl=c, splines=splines
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
        spacing: Spacing = "parameter",
        splines: list[Spline] | None = None,
        pose: PoseMode = "auto",
    ) -> tuple[np.ndarray, list[Frame | None]]:
        """Decode affine combinations of the curves' latent means (paper eqs. 9, 10), one per weight row.

        weights: (rows, len(curves)), rows summing to 1. With frame "auto" each interpolant
        comes back in the same blend of the inputs' frames. Length: n_points; else the
        inputs' common length, at the blend of their points' positions; else the model's.
        """
        prep = self.prepare(curves, frame, spacing, pose)
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
            out, ctrl = self.decode_model_splines(z)
            _check_finite(out, "weights", "the weighted latent decodes to non-finite coordinates: weights too extreme")
            given = [f for f in prep.frames if f is not None]
            frames: list[Frame | None] = (
                [blend_frames(given, w[r : r + 1])[0] for r in range(len(w))] if auto else [None] * len(w)
            )
            common = self._common_length(prep)
            blend = n_points is None and common is not None and all(f is not None for f in prep.fractions)
            if n_points is None and common is None:
                n_points = self.n_points
            results = []
            for r, o in enumerate(out):
                c = None if ctrl is None else ctrl[r]
                if blend:
                    positions = w[r] @ np.stack(prep.fractions)  # type: ignore[arg-type]
                    positions = np.maximum.accumulate(np.clip(positions, 0.0, 1.0))  # extrapolating rows stay ordered
                    results.append(
                        self._to_caller(o, frames[r], n_points=None, fractions=positions, ctrl=c, splines=splines)
                    )
                else:
                    results.append(
                        self._to_caller(o, frames[r], n_points=n_points, spacing=spacing, ctrl=c, splines=splines)
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

    def sample(
        self,
        count: int,
        *,
        seed: int | None = None,
        temperature: float = 1.0,
        prior: Prior | None = None,
        valid: bool = True,
        max_draws: int = MAX_DRAWS,
        n_points: int | None = None,
        spacing: Spacing = "parameter",
        frame: Frame | None = None,
        splines: list[Spline] | None = None,
    ) -> Sampled:
        """New curves from a latent distribution, decoded into the model plane (or mapped into `frame`).

        prior "learned": the Gaussian mixture fitted to the training curves' latent means (the default where the
        model ships one); "standard": the VAE's N(0, I). temperature scales the spread (see service/prior.py).
        valid: a draw whose curve crosses itself or leaves the data's disc is rejected and item i draws again, at
        most max_draws times in all. Item i's draws come from its own generator default_rng([seed, i]), so the
        seed decides every curve, across rejections too, and the first items of a larger count are the items of
        a smaller one.
        """
        chosen = prior or ("learned" if self.prior is not None else "standard")
        if chosen == "learned" and self.prior is None:
            raise InputError(
                ("prior",), 'this model ships no learned prior (GET /model: prior is null); use "standard"'
            )
        root = fresh_seed() if seed is None else seed
        rngs = [np.random.default_rng([root, i]) for i in range(count)]

        def draw(i: int) -> np.ndarray:
            if chosen == "learned":
                assert self.prior is not None
                return self.prior.draw(rngs[i], temperature)
            return rngs[i].standard_normal(self.latent_dim) * temperature

        z = np.array([draw(i) for i in range(count)]).reshape(count, self.latent_dim)
        draws, ok, todo = np.ones(count, np.int64), np.zeros(count, bool), np.arange(count)
        out = np.zeros((count, self.n_points, 2), np.float32)
        ctrl = np.zeros((count, len(self.knots) - self.spline_degree - 1, 2), np.float32) if self.has_splines else None
        while len(todo):  # each draw is decoded once; its curve is kept until the item draws again
            with np.errstate(all="ignore"):
                decoded, points = self.decode_model_splines(z[todo])
            out[todo] = decoded
            if ctrl is not None and points is not None:
                ctrl[todo] = points
            if not valid:
                break
            good = self.plausible(decoded.astype(np.float64))
            ok[todo[good]] = True
            todo = todo[~good & (draws[todo] < max_draws)]
            for i in todo:
                z[i] = draw(int(i))
                draws[i] += 1
        invalid = int((~ok).sum()) if valid else 0
        frames = [frame] * count if frame else None
        curves = self._place(out, ctrl, frames=frames, n_points=n_points, spacing=spacing, splines=splines)
        return Sampled(z, curves, chosen, rejected=int(draws.sum() - count), invalid=invalid)

    def plausible(self, curves: np.ndarray) -> np.ndarray:
        """(B, n, 2) model-plane curves -> (B,) bool: finite, free of self-intersections and inside the data's disc."""
        finite = np.isfinite(curves).all(axis=(1, 2))
        inside = np.linalg.norm(np.where(finite[:, None, None], curves, 0) - self.disc_center, axis=-1).max(axis=1)
        ok = finite & (inside <= self.disc_radius)
        if ok.any():
            ok[ok] = ~self_intersects(curves[ok])
        return ok


def fresh_seed() -> int:
    """A random seed for a request that gave none, reported back so the answer can be repeated."""
    return int(np.random.SeedSequence().generate_state(1, np.uint64)[0] >> np.uint64(11))  # 53 bits: exact in JSON


def curve_metrics(curves: Sequence[np.ndarray]) -> list[dict[str, Any]]:
    """Per curve, as the API reports it: smoothness (paper §3.4, degrees), self-intersection, length."""
    out = []
    for c in curves:
        with np.errstate(all="ignore"):
            smooth = {name: _number(v) for name, v in smoothness(c).items()}
            length = _number(curve_length(c))
        out.append({"smoothness": smooth, "self_intersects": bool(self_intersects(c)), "length": length})
    return out


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
