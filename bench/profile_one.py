"""Where a single-curve request's time goes in-process: `CurveRuntime.reconstruct` of one caller curve (`--curves N`:
of N, as one request), no cache, one 1-thread session pair, under cProfile; each stage's share of the time, and the
wall time per request without the profiler beside that of its two graphs alone (issue 39's "≤ 2× its graphs").
`--reading one-pass` (the default): pose "canonical", spacing "parameter" (one encoding, one decoding); `--reading
default`: what a request with default fields gets (the shipped model's learned reading).

    .venv/bin/python -m bench.profile_one                 # 300 requests
    .venv/bin/python -m bench.profile_one --markdown      # the table docs/BENCHMARKS.md shows
    .venv/bin/python -m bench.profile_one --reading default --markdown
    .venv/bin/python -m bench.profile_one --reading default --blas-threads 1   # numpy's BLAS as the service runs it
    .venv/bin/python -m bench.profile_one --reading default --blas-threads 1 --curves 128 --requests 6 --markdown

Stages are named by the functions they run (cumulative time), so the same script measures an older checkout too.
"""

from __future__ import annotations

import argparse
import cProfile
import pstats
import time
from pathlib import Path

import numpy as np

from bench import ceiling
from curve_vae.inference.model.cpus import limit_blas_threads
from curve_vae.inference.model.sessions import SessionConfig
from curve_vae.inference.reading import Reading
from curve_vae.inference.runtime import CurveRuntime

ROOT = Path(__file__).resolve().parents[1]
#: stage -> the functions (file suffix, name) whose cumulative time is the stage's
STAGES = {
    "the two graphs (onnxruntime)": [("graphs.py", "_run_graph")],
    "placement on the spline": [("matching.py", "ordered_closest_params")],
    "canonical frame": [("frame.py", "canonical_frame"), ("batch.py", "canonical_frames")],
    "to the model plane": [("reading.py", "model_points"), ("placing.py", "model_targets")],
    "back to the caller, MSE": [("placing.py", "to_caller"), ("placing.py", "placed_to_caller")],
}
ONE_PASS = Reading(pose="canonical", spacing="parameter")
#: the default request's stages: the candidates' poses and natural spacings, the ranker, then as one pass
DEFAULT_STAGES = {
    "the two graphs (onnxruntime)": STAGES["the two graphs (onnxruntime)"],
    "natural-spacing fit": [("natural.py", "natural_readings_of")],
    "of which the spacing guesser": [("spacer.py", "guesses")],  # inside the fit: not counted twice
    "candidate poses": [("frame.py", "pose_frames"), ("batch.py", "pose_frames_of")],
    "reading ranker": [("ranker.py", "scores")],
    "to the model plane": STAGES["to the model plane"],
    "placement on the spline": STAGES["placement on the spline"],
    "back to the caller, MSE": STAGES["back to the caller, MSE"],
}
READINGS = {"one-pass": (ONE_PASS, STAGES), "default": (Reading(), DEFAULT_STAGES)}


def measure(
    model_dir: Path, requests: int, reading: str = "one-pass", blas_threads: int | None = None, curves: int = 1
) -> dict[str, float]:
    asked, stages = READINGS[reading]
    rt = CurveRuntime.load(model_dir, sessions=SessionConfig(intra_op_threads=1), cache_bytes=0)
    if blas_threads is not None:
        limit_blas_threads(blas_threads)  # as the service does (inference/model/cpus.py)
    plane = ceiling.curves(curves, seed=1)
    one = list(ceiling.callers_curves(plane, seed=1))
    rt.reconstruct(one, asked)
    wall, cpu, graphs = _interleaved(rt, one, asked, np.asarray(plane, np.float32), requests)
    prof = cProfile.Profile()
    prof.enable()
    for _ in range(requests):
        rt.reconstruct(one, asked)
    prof.disable()
    stats = pstats.Stats(prof).stats  # type: ignore[attr-defined]
    total = max(ct for (_, _, name), (_, _, _, ct, _) in stats.items() if name == "reconstruct")
    out = {"wall_ms_per_request": wall, "cpu_ms_per_request": cpu, "graphs_ms_per_request": graphs}
    for stage, functions in stages.items():
        out[stage] = (
            sum(
                ct
                for (file, _, name), (_, _, _, ct, _) in stats.items()
                if any(file.endswith(f) and name == fn for f, fn in functions)
            )
            / total
        )
    out["everything else"] = 1.0 - sum(
        v for k, v in out.items() if not k.endswith("_ms_per_request") and not k.startswith("of which")
    )
    return out


def _interleaved(
    rt: CurveRuntime, one: list, asked: Reading, plane: np.ndarray, requests: int
) -> tuple[float, float, float]:
    """Milliseconds per request of the request (wall and this process's CPU, every thread's: a BLAS library's own
    threads count) and of its two graphs alone (the same curve, already in the model plane, wall), in alternating
    blocks of 50 so that both see the same machine."""
    spent = {"request": 0.0, "cpu": 0.0, "graphs": 0.0}
    for done in range(0, requests, 50):
        n = min(50, requests - done)
        start, cpu = time.perf_counter(), time.process_time()
        for _ in range(n):
            rt.reconstruct(one, asked)
        spent["request"] += time.perf_counter() - start
        spent["cpu"] += time.process_time() - cpu
        start = time.perf_counter()
        for _ in range(n):
            rt.graphs.decode(rt.graphs.encode(plane)[0])
        spent["graphs"] += time.perf_counter() - start
    return tuple(spent[k] / requests * 1e3 for k in ("request", "cpu", "graphs"))  # type: ignore[return-value]


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--model-dir", default=str(ROOT / "models"), help="the model (default: the shipped one)")
    p.add_argument("--requests", type=int, default=300, help="requests (default: 300)")
    p.add_argument("--curves", type=int, default=1, help="curves a request (default: 1)")
    p.add_argument("--reading", choices=list(READINGS), default="one-pass", help="the request's reading")
    p.add_argument(
        "--blas-threads", type=int, default=None, help="cap numpy's BLAS threads as the service does (default: its own)"
    )
    p.add_argument("--markdown", action="store_true", help="print a Markdown table")
    a = p.parse_args()
    r = measure(Path(a.model_dir), a.requests, a.reading, a.blas_threads, a.curves)
    if a.markdown:
        print("| stage | share of the request |\n|---|---|")
        for k, v in r.items():
            if not k.endswith("_ms_per_request"):
                print(f"| {k} | {100 * v:.0f}% |")
        wall, graphs = r["wall_ms_per_request"], r["graphs_ms_per_request"]
        print(f"| wall time per request, without the profiler | {wall:.2f} ms |")
        print(f"| CPU time per request, all threads | {r['cpu_ms_per_request']:.2f} ms |")
        print(f"| its two graphs alone, the same curve in the model plane | {graphs:.2f} ms ({wall / graphs:.2f}×) |")
    else:
        print({k: round(float(np.round(v, 4)), 4) for k, v in r.items()})


if __name__ == "__main__":
    main()
