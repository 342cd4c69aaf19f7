"""The in-process ceiling a server on this machine can approach, and onnxruntime against torch eager.

A "curve" here is one encoder run and one decoder run of the shipped graphs (what `/reconstruct` with pose
"as_is" costs the model), timed without HTTP, JSON or geometry:

    default     one session with onnxruntime's default options, batch 128, run from one thread
    per_core    one 1-thread session per core, each run from its own thread in parallel, batch 128
    eager       torch eager on the same weights (vae.pt), the same thread count, batch 1 and 128

The ceiling is the best of `default` and `per_core` (issue 16). Every measurement runs for `seconds` and
counts whole batches.
"""

from __future__ import annotations

import os
import threading
import time
from pathlib import Path
from typing import Any

import numpy as np
import onnxruntime as ort

from curve_vae.geometry import random_control_points, sample_bspline


def curves(count: int, seed: int = 0) -> np.ndarray:
    """(count, 161, 2) float32 curves of the paper's kind in the model plane."""
    return sample_bspline(random_control_points(np.random.default_rng(seed), count), 161).astype(np.float32)


def sessions(model_dir: Path, threads: int | None) -> tuple[ort.InferenceSession, ort.InferenceSession]:
    """Encoder and decoder sessions; threads None: onnxruntime's defaults (spinning included)."""
    opts = ort.SessionOptions()
    if threads is not None:
        opts.intra_op_num_threads = threads
        opts.inter_op_num_threads = 1
        opts.add_session_config_entry("session.intra_op.allow_spinning", "0")
    opts.log_severity_level = 3
    cpu = ["CPUExecutionProvider"]
    return (
        ort.InferenceSession(str(model_dir / "encoder.onnx"), opts, providers=cpu),
        ort.InferenceSession(str(model_dir / "decoder.onnx"), opts, providers=cpu),
    )


def _roundtrip(enc: ort.InferenceSession, dec: ort.InferenceSession, x: np.ndarray) -> None:
    mean = enc.run(["mean"], {"curves": x})[0]
    dec.run(None, {"latent": mean})


def _count(fn: Any, batch: int, seconds: float, stop_at: float | None = None) -> tuple[int, float]:
    """Curves done by calling fn() repeatedly for `seconds` (after one warm-up call), and the time taken."""
    fn()
    start = time.perf_counter()
    end = stop_at if stop_at is not None else start + seconds
    done = 0
    while time.perf_counter() < end:
        fn()
        done += batch
    return done, time.perf_counter() - start


def onnx_default(model_dir: Path, *, batch: int = 128, seconds: float = 5.0) -> float:
    """Curves/s: one session with default options, one thread calling it."""
    enc, dec = sessions(model_dir, None)
    x = curves(batch)
    done, took = _count(lambda: _roundtrip(enc, dec, x), batch, seconds)
    return done / took


def onnx_per_core(model_dir: Path, *, cores: int, batch: int = 128, seconds: float = 5.0) -> float:
    """Curves/s: `cores` 1-thread sessions, each run by its own thread, all at once."""
    pairs = [sessions(model_dir, 1) for _ in range(cores)]
    x = curves(batch)
    for enc, dec in pairs:
        _roundtrip(enc, dec, x)
    results: list[tuple[int, float]] = []
    stop_at = time.perf_counter() + seconds

    def loop(pair: tuple[ort.InferenceSession, ort.InferenceSession]) -> None:
        results.append(_count(lambda: _roundtrip(*pair, x), batch, seconds, stop_at))

    threads = [threading.Thread(target=loop, args=(pair,)) for pair in pairs]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    return sum(d for d, _ in results) / max(t for _, t in results)


def onnx_threads(model_dir: Path, *, threads: int, batch: int, seconds: float = 5.0) -> float:
    """Curves/s: one session of `threads` intra-op threads (spinning off), one caller."""
    enc, dec = sessions(model_dir, threads)
    x = curves(batch)
    done, took = _count(lambda: _roundtrip(enc, dec, x), batch, seconds)
    return done / took


def torch_eager(model_dir: Path, *, threads: int, batch: int, seconds: float = 5.0) -> float | None:
    """Curves/s of torch eager (no_grad, eval) on vae.pt with `threads` threads; None without torch or vae.pt."""
    try:
        import torch

        from curve_vae.training.model import VAE, ModelConfig
    except ImportError:
        return None
    weights = model_dir / "vae.pt"
    if not weights.is_file():
        return None
    before = torch.get_num_threads()
    torch.set_num_threads(threads)
    try:
        ckpt = torch.load(weights, map_location="cpu", weights_only=True)
        model = VAE(ModelConfig(**ckpt["model_config"]))
        model.load_state_dict(ckpt["model"])
        model.eval()
        x = torch.from_numpy(curves(batch))

        def roundtrip() -> None:
            with torch.inference_mode():
                model.decoder(model.encoder(x)[0])

        done, took = _count(roundtrip, batch, seconds)
        return done / took
    finally:
        torch.set_num_threads(before)


def breakdown(model_dir: Path, *, seconds: float = 3.0) -> dict[str, float]:
    """Milliseconds per request of what the server does besides HTTP, in-process on one 1-thread session: the raw
    encoder + decoder run; `CurveRuntime.reconstruct` with the default reading (the model's own) on curves in a
    caller's frame (turned, mirrored, spaced by arc length: geometry.canonical_frame's pose undone), with the fast
    path (pose "as_is", spacing "parameter") and with the search (pose and spacing "search"); and for 128 curves
    also parsing and validating the JSON body and rendering the answer. No encoding cache: every curve is read."""
    import orjson

    from curve_vae.inference.model.sessions import SessionConfig
    from curve_vae.inference.reading import Reading
    from curve_vae.inference.runtime import CurveRuntime
    from curve_vae.service.limits import check
    from curve_vae.service.routing import JSON
    from curve_vae.service.schemas import ReconstructRequest
    from curve_vae.service.settings import Settings

    runtime = CurveRuntime.load(model_dir, providers="cpu", sessions=SessionConfig(intra_op_threads=1), cache_bytes=0)
    settings = Settings()
    out: dict[str, float] = {}
    fast, search = Reading(pose="as_is", spacing="parameter"), Reading(pose="search", spacing="search")

    def ms(fn: Any) -> float:
        done, took = _count(fn, 1, seconds)
        return took / max(done, 1) * 1e3

    for batch in (1, 128):
        x = curves(batch, seed=batch)
        posted = callers_curves(x, seed=batch)
        out[f"onnx_b{batch}_ms"] = ms(lambda x=x: runtime.graphs.decode(runtime.graphs.encode(x)[0]))
        out[f"reconstruct_default_b{batch}_ms"] = ms(lambda c=posted: runtime.reconstruct(c))
        out[f"reconstruct_fast_b{batch}_ms"] = ms(lambda c=posted: runtime.reconstruct(c, fast))
        if batch == 1:
            out["reconstruct_search_b1_ms"] = ms(lambda c=posted: runtime.reconstruct(c, search))
        body = orjson.dumps({"curves": np.stack(posted)}, option=orjson.OPT_SERIALIZE_NUMPY)

        def parse(body: bytes = body) -> None:
            check(ReconstructRequest.model_validate(orjson.loads(body)), settings)

        out[f"parse_validate_b{batch}_ms"] = ms(parse)
        rec = runtime.reconstruct(posted)
        out[f"render_b{batch}_ms"] = ms(lambda rec=rec: JSON({"curves": rec.curves, "mse": rec.mse}))
    return out


def callers_curves(model_plane: np.ndarray, *, seed: int) -> list[np.ndarray]:
    """Curves as a caller sends them: each of the paper's curves turned by a random angle, mirrored or reversed at
    random, scaled to pixel coordinates with y down, its 161 points spaced by arc length."""
    from curve_vae.geometry import resample

    rng = np.random.default_rng(seed)
    out = []
    for c in model_plane.astype(np.float64):
        a = rng.uniform(0, 2 * np.pi)
        turn = np.array([[np.cos(a), np.sin(a)], [-np.sin(a), np.cos(a)]])
        c = (c - 64) @ turn * ([-1.0, 1.0] if rng.random() < 0.5 else 1.0)
        c = (c[::-1] if rng.random() < 0.5 else c) * [3.0, -3.0] + [400.0, 300.0]
        out.append(resample(c, len(c)).round(2))
    return out


def posted(count: int, seed: int) -> np.ndarray:
    """(count, 161, 2): `count` of the paper's curves as a caller posts them (`callers_curves` of `curves`, one seed
    for both): the bodies bench.serve and bench.sweep send."""
    return np.stack(callers_curves(curves(count, seed=seed), seed=seed))


def measure(
    model_dir: Path, *, seconds: float = 5.0, cores: int | None = None, eager: bool = True, details: bool = True
) -> dict[str, Any]:
    """All in-process figures of the report; the ceiling is the best of default and per-core; `eager` adds C,
    `details` the breakdown of a request."""
    cores = cores or len(os.sched_getaffinity(0))
    out: dict[str, Any] = {"cores": cores}
    out["default_b128"] = onnx_default(model_dir, seconds=seconds)
    out["per_core_b128"] = onnx_per_core(model_dir, cores=cores, seconds=seconds)
    out["ceiling"] = max(out["default_b128"], out["per_core_b128"])
    if details:
        out["breakdown"] = breakdown(model_dir, seconds=min(0.6 * seconds, 3.0))  # 3 s a row in a full run
    for batch in (1, 128) if eager else ():
        ort_rate = onnx_threads(model_dir, threads=1, batch=batch, seconds=seconds)
        eager = torch_eager(model_dir, threads=1, batch=batch, seconds=seconds)
        out[f"onnx_1t_b{batch}"] = ort_rate
        out[f"torch_1t_b{batch}"] = eager
        out[f"C_b{batch}"] = ort_rate / eager if eager else None
    return out


if __name__ == "__main__":
    import json

    print(json.dumps(measure(Path(__file__).resolve().parent.parent / "models", seconds=3.0), indent=1))
