"""The default reading with this checkout's natural-spacing fit against another revision's, per set: the mean relative
RMSE of each (and their ratio), how many answers changed, and the time of each fit (starts, steps and all), the rest
of the reading the same.

    .venv/bin/python -m bench.paired_fit                       # against HEAD's geometry/natural.py, 100 curves a set
    .venv/bin/python -m bench.paired_fit --against 5ba0dc1 --count 200

The other revision's geometry/natural.py is loaded from git beside this checkout's and swapped in for the fit alone
(the sets: scripts/paired_readings.py's family suite, closed outlines and analytic shapes). One intra-op thread, no
cache, numpy's BLAS on one thread as the service runs it.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

from bench.revisions import module_at
from curve_vae.geometry import closeness
from curve_vae.geometry import natural as fit_now
from curve_vae.inference.model.cpus import limit_blas_threads
from curve_vae.inference.runtime import CurveRuntime

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "scripts"))
from paired_readings import curve_sets  # noqa: E402


def fit_of(revision: str):  # noqa: ANN201 - a module
    """geometry/natural.py as it is at `revision`, as a module of its own."""
    return module_at(revision, "geometry/natural.py", f"curve_vae.geometry.natural_{revision}")


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--against", default="HEAD", help="the revision whose fit is the reference (default HEAD)")
    p.add_argument("--count", type=int, default=100)
    p.add_argument("--sets", nargs="*", help="only these sets")
    args = p.parse_args()
    limit_blas_threads(1)
    rt = CurveRuntime.load(ROOT / "models", providers="cpu", intra_op_threads=1, cache_bytes=0)
    old, new = fit_of(args.against)._BatchFit, fit_now._BatchFit
    sets = curve_sets(args.count)
    fit_now.natural_readings_of([next(iter(sets.values()))[0]])  # compiled code loaded (or compiled) before timing
    print(f"| set | error, {args.against}'s fit | error, this fit | ratio | answers changed | fit time, ratio |")
    print("|---|---|---|---|---|---|")
    for name, curves in sets.items():
        if args.sets and name not in args.sets:
            continue
        errors, seconds = {}, {}
        fit_whole = fit_now._fit
        for label, fit in (("old", old), ("new", new)):
            fit_now._BatchFit = fit
            spent = [0.0]

            def timed(*a, spent=spent, fit_whole=fit_whole, **k):  # type: ignore[no-untyped-def]
                t0 = time.perf_counter()
                out = fit_whole(*a, **k)
                spent[0] += time.perf_counter() - t0
                return out

            fit_now._fit = timed
            try:
                out = rt.reconstruct(curves).curves
            finally:
                fit_now._fit = fit_whole
            errors[label] = closeness(curves, list(out))[0]
            seconds[label] = spent[0]
        fit_now._BatchFit = new
        a, b = errors["old"].mean(), errors["new"].mean()
        changed = np.mean(np.abs(errors["new"] - errors["old"]) > 1e-6 * a)
        print(
            f"| {name} | {100 * a:.4f}% | {100 * b:.4f}% | {b / a:.4f} | {100 * changed:.0f}% "
            f"| {seconds['new'] / max(seconds['old'], 1e-9):.2f} |"
        )


if __name__ == "__main__":
    main()
