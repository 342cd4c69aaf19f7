"""One exported model's ONNX graphs as the runtime runs them, the encoder and decoder and the learned parts beside
them (the reading ranker, the spacing guesser): opened, checked and warmed up, then run raw, each run counted and a
cancellation checkpoint.

`ModelGraphs.open(model_dir, manifest)` opens one encoder/decoder session pair per inference thread
(`inference.model.sessions`), checks the graphs' signatures against the manifest and runs a warm-up. `encode_model` and
`decode_model` take and return model-plane arrays in runs of `batch_size`, through the thread's micro-batcher when
it has one, each run a cancellation checkpoint (below). `CurveRuntime` (inference.runtime) builds the caller's
frames, lengths and poses on top.

Abandoned work stops: a request whose client has gone, or which ran past its time limit, is cancelled, and the
inference thread running it stops at its next checkpoint — before each run of a graph, between chunks — instead of
computing to the end.

    token = CancelToken()
    with cancellable(token):      # on the inference thread
        runtime.reconstruct(...)  # raises Cancelled at the next checkpoint once token.cancel() is called

`checkpoint()` is a no-op outside `cancellable`, so offline callers (the command line, training's evaluation) pay
nothing for it.
"""

from __future__ import annotations

import threading
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Self

import numpy as np
import onnxruntime as ort

from curve_vae.errors import CancelledWork, InvalidInput
from curve_vae.geometry import clamped_uniform_knots
from curve_vae.inference.choices import Providers
from curve_vae.inference.model import batching
from curve_vae.inference.model.manifest import ENCODER_OUTPUTS, Manifest, ModelLoadError, decoder_outputs
from curve_vae.inference.model.sessions import SessionConfig, SessionPool, open_pair, resolve_providers


class ModelGraphs:
    """The sessions of one exported model, its encoder's and decoder's (a pair per inference thread) and its learned
    parts' (`add_part`), and the dimensions its manifest gives them."""

    def __init__(
        self,
        pool: SessionPool,
        manifest: Manifest,
        *,
        batch_size: int = 64,
        requested_providers: Providers = "cpu",
    ) -> None:
        self.pool = pool  # the pair of each inference thread
        self.manifest = manifest
        self.batch_size = batch_size
        self.requested_providers = requested_providers
        self.n_points = manifest.n_points
        self.latent_dim = manifest.latent_dim
        self.model_size = manifest.frame.model_size
        spline = manifest.spline
        self.spline_degree = spline.degree if spline else 0
        self.knots = clamped_uniform_knots(spline.n_ctrl, spline.degree) if spline else None
        self.n_ctrl = spline.n_ctrl if spline else 0
        self.has_params = bool(spline and spline.learned_params)
        self.rows = {"encoder": 0, "decoder": 0}  # rows each graph has run: what requests cost, for /metrics
        self.parts: dict[str, tuple[ort.InferenceSession, str]] = {}  # learned parts: one shared session each
        encoder, decoder = pool.pairs[0]
        self._enc_in = encoder.get_inputs()[0].name
        self._dec_in = decoder.get_inputs()[0].name
        self._check_signature()

    @classmethod
    def open(
        cls,
        model_dir: str | Path,
        manifest: Manifest,
        *,
        providers: Providers = "auto",
        sessions: SessionConfig | None = None,
        batch_size: int = 64,
        warm_up: bool = True,
    ) -> Self:
        """Open a model directory's graphs; ModelLoadError says what to fix when they cannot serve."""
        root = Path(model_dir)
        provider_list = resolve_providers(providers)
        config = sessions or SessionConfig()
        paths = (root / manifest.graphs.encoder.file, root / manifest.graphs.decoder.file)
        pool = SessionPool(
            [open_pair(paths, provider_list, config, require_cuda=providers == "cuda") for _ in range(config.sessions)]
        )
        graphs = cls(pool, manifest, batch_size=batch_size, requested_providers=providers)
        if warm_up:
            graphs.warm_up()
        return graphs

    def _check_signature(self) -> None:
        enc_in, dec_in = self.encoder.get_inputs()[0], self.decoder.get_inputs()[0]
        enc_out = {o.name for o in self.encoder.get_outputs()}
        problems = []
        if list(enc_in.shape[1:]) != [self.n_points, 2]:
            problems.append(
                f"encoder input {enc_in.name} has shape {enc_in.shape}, expected [batch, {self.n_points}, 2]"
            )
        if not set(ENCODER_OUTPUTS) <= enc_out:
            problems.append(f"encoder outputs {sorted(enc_out)}, expected mean and log_var")
        if list(dec_in.shape[1:]) != [self.latent_dim]:
            problems.append(
                f"decoder input {dec_in.name} has shape {dec_in.shape}, expected [batch, {self.latent_dim}]"
            )
        dec_out = [o.name for o in self.decoder.get_outputs()]
        expected = decoder_outputs(self.has_splines, self.has_params)
        if dec_out[: len(expected)] != expected:
            problems.append(f"decoder outputs {dec_out}, expected {', '.join(expected)} (the manifest's spline)")
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
    def onnxruntime_version(self) -> str:
        """The onnxruntime release the graphs run on (GET /model states it)."""
        return str(ort.__version__)

    @property
    def providers(self) -> list[str]:
        """Providers the sessions actually run on (a fallback shows here)."""
        return list(self.encoder.get_providers())

    def warm_up(self) -> None:
        """One full encode → decode round trip; raises ModelLoadError if the graphs misbehave."""
        t = np.linspace(0.0, np.pi, self.n_points)
        circle = np.stack([64 + 40 * np.cos(t), 64 + 40 * np.sin(t)], axis=1)[None].astype(np.float32)
        try:
            mean, log_var = self.encode(circle)
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

    def encode(self, curves: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(B, n_points, 2) in the model plane -> mean, log_var (B, latent_dim); split into runs of batch_size."""
        x = np.ascontiguousarray(curves, dtype=np.float32)
        encoder = self.encoder
        means, log_vars = [], []
        for i in range(0, len(x), self.batch_size):
            mean, log_var = self._run_graph(encoder, "encoder", x[i : i + self.batch_size], list(ENCODER_OUTPUTS))
            means.append(mean)
            log_vars.append(log_var)
        if not means:
            return np.zeros((0, self.latent_dim), np.float32), np.zeros((0, self.latent_dim), np.float32)
        return np.concatenate(means), np.concatenate(log_vars)

    def _run_graph(
        self, session: ort.InferenceSession, graph: str, x: np.ndarray, outputs: list[str] | None
    ) -> list[np.ndarray]:
        """One run of a graph: gathered with other requests' by the thread's micro-batcher, if it has one; first, a
        cancelled request stops here."""
        checkpoint()
        self.rows[graph] += len(x)
        batcher = batching.current()
        if batcher is not None:
            return batcher.run(graph, x, outputs)
        return session.run(outputs, {self._enc_in if graph == "encoder" else self._dec_in: x})

    def add_part(self, name: str, path: str | Path, *, shape: tuple[int | None, ...], sessions: SessionConfig) -> None:
        """Open a learned part's graph (the reading ranker, the spacing guesser: exported by training/parts.py) beside
        the model's, on the providers they run on: one session every inference thread shares, whose input must be
        (batch, *shape) (None: any size); else InvalidInput saying what it takes. A numpy .npz of weights (a model
        from before 0.14.0) is refused with how to convert it."""
        path = Path(path)
        if path.suffix == ".npz":
            raise InvalidInput(
                "numpy weights, which this runtime no longer reads: convert them to ONNX with "
                f"`curve-vae {path.stem} export {path} --model-dir {path.parent} --force` (the training extra)"
            )
        try:
            session = ort.InferenceSession(str(path), sess_options=sessions.options(), providers=self.providers)
        except Exception as e:  # onnxruntime raises its own exception types
            raise InvalidInput(f"onnxruntime cannot open it: {e}") from e
        inp = session.get_inputs()[0]
        got = [d if isinstance(d, int) else None for d in inp.shape]
        want = [None, *shape]
        if len(got) != len(want) or any(w is not None and g != w for g, w in zip(got, want)):
            raise InvalidInput(f"its graph takes {_shape(got)}; this part takes {_shape(want)}")
        self.parts[name] = (session, inp.name)
        self.rows[name] = 0

    def run_part(self, name: str, inputs: np.ndarray) -> np.ndarray:
        """A learned part's output for (batch, …) float32 inputs; as every run of a graph, counted in `rows` and, first,
        a cancellation checkpoint."""
        checkpoint()
        session, input_name = self.parts[name]
        self.rows[name] += len(inputs)
        return session.run(None, {input_name: np.ascontiguousarray(inputs, np.float32)})[0]

    def decode_model(self, latents: np.ndarray) -> np.ndarray:
        """(B, latent_dim) -> (B, n_points, 2) in the model plane."""
        return self.decode(latents)[0]

    def decode(self, latents: np.ndarray) -> tuple[np.ndarray, np.ndarray | None, np.ndarray | None]:
        """(B, latent_dim) -> curves (B, n_points, 2); with a B-spline head, control points (B, n_ctrl, 2); with
        learned parameters (`has_params`), the spline parameter of each point (B, n_points). Absent: None."""
        z = np.ascontiguousarray(latents, dtype=np.float32)
        decoder = self.decoder
        parts: list[list[np.ndarray]] = [[], [], []]
        for i in range(0, len(z), self.batch_size):
            for part, out in zip(parts, self._run_graph(decoder, "decoder", z[i : i + self.batch_size], None)):
                part.append(out)
        empty = (np.zeros((0, self.n_points, 2)), np.zeros((0, self.n_ctrl, 2)), np.zeros((0, self.n_points)))
        curves, ctrl, params = (np.concatenate(p) if p else e.astype(np.float32) for p, e in zip(parts, empty))
        return curves, ctrl if self.has_splines else None, params if self.has_params else None


def _shape(dims: list[int | None]) -> str:
    return "(" + ", ".join("any" if d is None else str(d) for d in dims) + ")"


class Cancelled(CancelledWork):
    """The work was abandoned: its client went away, or it passed its time limit."""


class CancelToken:
    """Set from any thread (the event loop's), read on the inference thread."""

    def __init__(self) -> None:
        self._event = threading.Event()
        self.reason = ""

    def cancel(self, reason: str) -> None:
        if not self._event.is_set():
            self.reason = reason
            self._event.set()

    @property
    def cancelled(self) -> bool:
        return self._event.is_set()

    def check(self) -> None:
        if self._event.is_set():
            raise Cancelled(self.reason)


_local = threading.local()


@contextmanager
def cancellable(token: CancelToken) -> Iterator[CancelToken]:
    """Make `token` the calling thread's for the block: `checkpoint()` raises Cancelled once it is cancelled."""
    before = getattr(_local, "token", None)
    _local.token = token
    try:
        yield token
    finally:
        _local.token = before


def checkpoint() -> None:
    """Raise Cancelled if the calling thread's work was cancelled (a no-op outside `cancellable`)."""
    token = getattr(_local, "token", None)
    if token is not None:
        token.check()
