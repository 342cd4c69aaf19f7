"""One exported model's two ONNX graphs as the service runs them: opened, checked and warmed up, then run raw.

`ModelGraphs.load(model_dir)` reads and checks the manifest (`inference.model_files`), opens one encoder/decoder
session pair per inference thread (`inference.sessions`), checks the graphs' signatures against the manifest, reads
the learned prior and runs a warm-up. `encode_model` and `decode_model(_splines)` take and return model-plane
arrays in runs of `batch_size`, through the thread's micro-batcher when it has one. `CurveRuntime`
(inference.runtime) builds the caller's frames, lengths and poses on top.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, Self

import numpy as np
import onnxruntime as ort

from curve_vae.geometry import clamped_uniform_knots
from curve_vae.geometry.frame import MODEL_CENTER
from curve_vae.inference import batching
from curve_vae.inference.model_files import ModelLoadError, graph_file, read_manifest, resolve_providers
from curve_vae.inference.prior import PRIOR_FILE, LatentPrior
from curve_vae.inference.sessions import SessionConfig, SessionPool, open_pair


class ModelGraphs:
    """The encoder and decoder sessions of one exported model, its manifest's dimensions and its prior."""

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
        self.learned_params = bool(spline and spline.get("learned_params"))
        # how a reconstruction's points are placed (training.export.PLACEMENTS): at the input points' closest points on
        # the decoded spline, or at the head's parameters (manifests written before placements: index)
        self.closest_placement = bool(spline and spline.get("placement") == "closest")
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
        placement: str = "model",
    ) -> Self:
        """Open a model directory; raises ModelLoadError with what to fix when it cannot serve.

        `sessions` sets threads, spinning and the number of session pairs (inference.sessions); without it, one pair
        of `intra_op_threads` threads. `placement`: "model" places a reconstruction's points as the manifest's
        spline.placement says; "closest" or "index" whatever it says (CURVE_VAE_PLACEMENT)."""
        root = Path(model_dir)
        manifest = read_manifest(root)
        provider_list = resolve_providers(providers)
        config = sessions or SessionConfig(intra_op_threads=intra_op_threads)
        paths = (root / graph_file(manifest, "encoder"), root / graph_file(manifest, "decoder"))
        pool = SessionPool(
            [open_pair(paths, provider_list, config, require_cuda=providers == "cuda") for _ in range(config.sessions)]
        )
        spline = manifest.get("spline")
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
        if placement not in ("model", "closest", "index"):
            raise ValueError(f"placement must be model, closest or index, got {placement!r}")
        if placement == "closest" and not spline:
            raise ModelLoadError(f"{root}: placement closest needs a model with a B-spline head; this one has none")
        if placement != "model":
            runtime.closest_placement = placement == "closest"
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
        expected = ["curves", "control_points", "params"][: 1 + self.has_splines + self.has_params]
        if dec_out[: len(expected)] != expected:
            problems.append(f"decoder outputs {dec_out}, expected {', '.join(expected)} (the manifest's spline)")
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
    def has_params(self) -> bool:
        """Whether the decoder places its points at spline parameters of its own (output `params`), not evenly."""
        return self.learned_params  # read from the manifest's spline entry: never without a head

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

    def decode_model_splines(self, latents: np.ndarray) -> tuple[np.ndarray, np.ndarray | None, np.ndarray | None]:
        """(B, latent_dim) -> curves (B, n_points, 2); with a B-spline head, control points (B, n_ctrl, 2); with
        learned parameters (`has_params`), the spline parameter of each point (B, n_points). Absent: None."""
        z = np.ascontiguousarray(latents, dtype=np.float32)
        decoder = self.decoder
        parts: list[list[np.ndarray]] = [[], [], []]
        for i in range(0, len(z), self.batch_size):
            for part, out in zip(parts, self._run_graph(decoder, "decoder", z[i : i + self.batch_size], None)):
                part.append(out)
        n_ctrl = len(self.knots) - self.spline_degree - 1 if self.knots is not None else 0
        empty = (np.zeros((0, self.n_points, 2)), np.zeros((0, n_ctrl, 2)), np.zeros((0, self.n_points)))
        curves, ctrl, params = (np.concatenate(p) if p else e.astype(np.float32) for p, e in zip(parts, empty))
        return curves, ctrl if self.has_splines else None, params if self.has_params else None
