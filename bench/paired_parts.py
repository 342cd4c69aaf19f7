"""The default reading with this checkout's ranker and spacing guesser against another revision's, per set: the mean
relative RMSE of each (and their ratio), how many answers changed, and the time the two parts took, the rest of the
reading the same.

    .venv/bin/python -m bench.paired_parts --against 7a1a581          # 0.23.0's numpy forward passes, 100 a set
    .venv/bin/python -m bench.paired_parts --against 7a1a581 --count 200

The other revision's inference/ranker.py and inference/spacer.py (with what they import that this checkout no longer
has) are loaded from git, with its models/ranker.* and spacer.* files, and swapped in for the two parts alone (the
sets: scripts/paired_readings.py's family suite, closed outlines and analytic shapes). One intra-op thread, no
cache, numpy's BLAS on one thread as the service runs it.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

from bench.revisions import module_at, saved, show
from curve_vae.geometry import closeness
from curve_vae.inference.model.cpus import limit_blas_threads
from curve_vae.inference.runtime import CurveRuntime

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "scripts"))
from paired_readings import curve_sets  # noqa: E402


def parts_of(revision: str) -> tuple[Any, Any]:
    """The revision's ranker and guesser, loaded from its own files and weights (numpy .npz before 0.24.0)."""
    manifest = json.loads(show(revision, "models/manifest.json"))
    out = []
    for name in ("ranker", "spacer"):
        file = manifest[name]["file"]
        if not file.endswith(".npz"):
            raise SystemExit(f"{revision}'s {name} is a graph already: compare models with scripts/paired_readings.py")
        module_at(revision, "inference/weights.py", "curve_vae.inference.weights", register=True)
        module = module_at(revision, f"inference/{name}.py", f"curve_vae.inference.{name}", register=True)
        out.append(getattr(module, name.capitalize()).load(saved(revision, f"models/{file}")))
    return out[0], out[1]


class _Timed:
    """A part whose calls are timed (the ranker's scores, the guesser's guesses)."""

    def __init__(self, part: Any, method: str) -> None:
        self.part, self.method, self.seconds = part, method, 0.0

    def __getattr__(self, name: str) -> Any:
        attr = getattr(self.part, name)
        if name != self.method:
            return attr

        def timed(*a: Any, **k: Any) -> Any:
            t0 = time.perf_counter()
            try:
                return attr(*a, **k)
            finally:
                self.seconds += time.perf_counter() - t0

        return timed


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--against", required=True, help="the revision whose ranker and guesser are the reference")
    p.add_argument("--count", type=int, default=100)
    args = p.parse_args()
    limit_blas_threads(1)
    rt = CurveRuntime.load(ROOT / "models", providers="cpu", intra_op_threads=1, cache_bytes=0)
    reader = rt.reader
    parts = {"old": parts_of(args.against), "new": (reader.ranker, reader.spacer)}
    sets = curve_sets(args.count)
    rt.reconstruct(next(iter(sets.values()))[:4])  # compiled code loaded (or compiled) before timing
    print(f"| set | error, {args.against}'s parts | error, these | ratio | answers changed | parts' time, ratio |")
    print("|---|---|---|---|---|---|")
    for name, curves in sets.items():
        errors, seconds = {}, {}
        for label, (ranker, spacer) in parts.items():
            reader.ranker, reader.spacer = _Timed(ranker, "scores"), _Timed(spacer, "guesses")
            errors[label] = closeness(curves, list(rt.reconstruct(curves).curves))[0]
            seconds[label] = reader.ranker.seconds + reader.spacer.seconds
        reader.ranker, reader.spacer = parts["new"]
        a, b = errors["old"].mean(), errors["new"].mean()
        changed = np.mean(np.abs(errors["new"] - errors["old"]) > 1e-6 * a)
        print(
            f"| {name} | {100 * a:.4f}% | {100 * b:.4f}% | {b / a:.4f} | {100 * changed:.0f}% "
            f"| {seconds['new'] / max(seconds['old'], 1e-9):.2f} |",
            flush=True,
        )


if __name__ == "__main__":
    main()
