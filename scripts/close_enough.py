"""Pose "learned" reads a curve's second-ranked candidate only where its first came back farther than CLOSE_ENOUGH
(inference.picking): per set, against reading both always (CLOSE_ENOUGH 0), the mean relative RMSE, the farthest any
single curve moved, the share of curves read once, the encoder rows a curve and the time.

    .venv/bin/python scripts/close_enough.py --count 200                   # the shipped CLOSE_ENOUGH
    .venv/bin/python scripts/close_enough.py --count 200 --taus 0.0005 0.0007 0.001

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
from curve_vae.inference import picking
from curve_vae.inference.cpus import limit_blas_threads
from curve_vae.inference.runtime import CurveRuntime

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "scripts"))
from paired_readings import curve_sets  # noqa: E402


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--count", type=int, default=200, help="curves per suite set and closed outlines (default: 200)")
    p.add_argument("--taus", type=float, nargs="+", default=[picking.CLOSE_ENOUGH])
    a = p.parse_args()
    limit_blas_threads(1)
    rt = CurveRuntime.load(ROOT / "models", providers="cpu", intra_op_threads=1, cache_bytes=0)
    sets = curve_sets(a.count)
    rt.reconstruct(next(iter(sets.values()))[:4])  # compiled code loaded (or compiled) before timing
    both: dict[str, tuple[np.ndarray, float]] = {}
    print("| CLOSE_ENOUGH | set | error ÷ both always | farthest curve ÷ | read once | encoder rows a curve | time ÷ |")
    print("|---|---|---|---|---|---|---|")
    for tau in [0.0, *a.taus]:
        picking.CLOSE_ENOUGH = tau
        for name, curves in sets.items():
            rows = rt.graphs.rows["encoder"]
            t0 = time.perf_counter()
            out = rt.reconstruct(curves).curves
            seconds = time.perf_counter() - t0
            per_curve = (rt.graphs.rows["encoder"] - rows) / len(curves)
            e = closeness(curves, list(out))[0]
            if tau == 0.0:
                both[name] = (e, seconds)
                continue
            ref, ref_seconds = both[name]
            print(
                f"| {tau} | {name} | {e.mean() / ref.mean():.4f} | {np.max(e / ref):.2f} | {2 - per_curve:.0%} "
                f"| {per_curve:.2f} | {seconds / ref_seconds:.2f} |",
                flush=True,
            )


if __name__ == "__main__":
    main()
