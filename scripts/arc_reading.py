"""The learned reading keeping the arc-length start's natural reading for every curve, against for loops and curves with
a corner alone (inference.reader.GUESSED_ARC_READING): curve by curve, the answers crossing themselves, the time.

    .venv/bin/python scripts/arc_reading.py [--count 200] [--json out.json]

The sets are scripts/paired_readings.py's (the family suite, closed outlines, the reading table's analytic shapes);
each set's change of the mean relative RMSE comes with its 95% bootstrap interval. One intra-op thread, no encoding
cache; the times are CPU seconds for all the sets, each way once (this machine drifts: a guide, not a benchmark).
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from pathlib import Path

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")  # one core, as the service's inference threads run

import numpy as np  # noqa: E402

from curve_vae.geometry import self_intersects  # noqa: E402
from curve_vae.inference import reader  # noqa: E402
from curve_vae.inference.reading import Reading  # noqa: E402
from curve_vae.inference.runtime import CurveRuntime  # noqa: E402
from curve_vae.training.suite import relative_rmse  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))
from paired_readings import curve_sets, paired  # noqa: E402

WAYS = ("always", "loops_and_corners")


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--model-dir", default="models")
    p.add_argument("--count", type=int, default=200, help="curves per set (default: 200)")
    p.add_argument("--json", default="", help="also write the rows here")
    a = p.parse_args()
    rt = CurveRuntime.load(a.model_dir, intra_op_threads=1, cache_bytes=0)
    sets = curve_sets(a.count)
    errors: dict[str, dict[str, np.ndarray]] = {}
    crossing: dict[str, dict[str, float]] = {}  # the share of answers crossing themselves where the input does not
    seconds = {}
    for way in WAYS:
        reader.GUESSED_ARC_READING = way
        start = time.process_time()
        answers = {n: rt.reconstruct(c, Reading()).curves for n, c in sets.items()}
        seconds[way] = time.process_time() - start
        errors[way] = {n: 100 * relative_rmse(sets[n], out) for n, out in answers.items()}
        crossing[way] = {
            n: float(np.mean([self_intersects(o) and not self_intersects(c) for c, o in zip(sets[n], out)]))
            for n, out in answers.items()
        }
    rng = np.random.default_rng(0)
    rows = {name: paired(errors["always"][name], errors["loops_and_corners"][name], rng) for name in sets}
    for name, r in rows.items():
        r["crossing_always"], r["crossing_corners"] = crossing["always"][name], crossing["loops_and_corners"][name]
    print("| set | every curve | loops and corners | change, 95% interval | curves changed | crossing |")
    print("|---|---|---|---|---|---|")
    for name, r in rows.items():
        print(
            f"| {name} | {r['before']:.4f}% | {r['after']:.4f}% | {100 * r['change']:+.1f}% "
            f"({100 * r['low']:+.1f} to {100 * r['high']:+.1f}) | {100 * r['changed_curves']:.0f}% "
            f"| {100 * r['crossing_always']:.1f}% → {100 * r['crossing_corners']:.1f}% |"
        )
    print(f"CPU seconds, every curve / loops and corners: {seconds['always']:.1f} / {seconds['loops_and_corners']:.1f}")
    if a.json:
        Path(a.json).write_text(json.dumps({"sets": rows, "cpu_seconds": seconds}, indent=2))


if __name__ == "__main__":
    main()
