"""How far the ranker can be trusted alone: pose "learned" encodes a curve's first candidate alone where the ranker
expects its second to come back more than a margin farther (inference.reader.CONFIDENT_MARGIN), else both. For each
margin, per set: the mean relative RMSE against both always (inf), the share of curves encoded once, and the time.

    .venv/bin/python scripts/confident_ranker.py --count 100 --margins inf 1.0 0.5 0.25

The sets: scripts/paired_readings.py's family suite, closed outlines and analytic shapes. One intra-op thread, no
cache, numpy's BLAS on one thread as the service runs it.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

from curve_vae.geometry import closeness
from curve_vae.inference import reader as reader_module
from curve_vae.inference.cpus import limit_blas_threads
from curve_vae.inference.runtime import CurveRuntime

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "scripts"))
from paired_readings import curve_sets  # noqa: E402


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--count", type=int, default=100, help="curves per suite set and closed outlines (default: 100)")
    p.add_argument("--margins", type=float, nargs="+", default=[float("inf"), 1.0, 0.5, 0.25])
    a = p.parse_args()
    limit_blas_threads(1)
    rt = CurveRuntime.load(ROOT / "models", providers="cpu", intra_op_threads=1, cache_bytes=0)
    sets = curve_sets(a.count)
    rt.reconstruct(next(iter(sets.values()))[:4])  # compiled code loaded (or compiled) before timing
    errors: dict[float, dict[str, np.ndarray]] = {}
    print("| margin | set | error ÷ both always | worst curve ÷ | encoded once | encoder rows | seconds |")
    print("|---|---|---|---|---|---|---|")
    for margin in a.margins:
        reader_module.CONFIDENT_MARGIN = margin
        errors[margin] = {}
        for name, curves in sets.items():
            rows = rt.graphs.rows["encoder"]
            t0 = time.perf_counter()
            out = rt.reconstruct(curves).curves
            seconds = time.perf_counter() - t0
            rows = rt.graphs.rows["encoder"] - rows
            e = errors[margin][name] = closeness(curves, list(out))[0]
            ref = errors[a.margins[0]][name]
            once = 2 - rows / len(curves)
            print(
                f"| {margin} | {name} | {e.mean() / ref.mean():.4f} | {np.max(e / ref):.2f} | {100 * once:.0f}% "
                f"| {rows} | {seconds:.1f} |",
                flush=True,
            )


if __name__ == "__main__":
    main()
