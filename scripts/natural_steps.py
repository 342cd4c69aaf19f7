"""The learned reading with the natural fit's own steps and with fewer: the family suite per set, beside the search.

    .venv/bin/python scripts/natural_steps.py [--count 200] [--steps 15/40 8/24] [--json out.json]

Each STEPS is SCOUT/TOTAL Levenberg–Marquardt steps of geometry.natural_readings_of (every start scouts SCOUT
steps, the closest and the arc-length one go on to TOTAL), set as the reader's LEARNED_NATURAL_STEPS; the search
runs once, with the fit's own 15/40. Rows: each suite set's mean relative RMSE (% of the diagonal) per
variant, and the whole suite's wall time. One intra-op thread, no encoding cache. docs/RESULTS.md "Fewer
natural-fit steps for the learned reading" is its output with the defaults.
"""

from __future__ import annotations

import argparse
import json
import os
import time

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")  # one core, as the service's inference threads run

from curve_vae.inference import reader  # noqa: E402
from curve_vae.inference.runtime import CurveRuntime  # noqa: E402
from curve_vae.inference.sessions import SessionConfig  # noqa: E402
from curve_vae.training.suite import paper_test_split, run_suite, suite_sets  # noqa: E402

SEARCH = {"pose": "search", "spacing": "search"}
LEARNED = {"pose": "learned", "spacing": "search"}


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--model-dir", default="models", help="the model (default: models)")
    p.add_argument("--count", type=int, default=200, help="curves per suite set (default: 200)")
    p.add_argument("--steps", nargs="+", default=["15/40", "8/24"], help="SCOUT/TOTAL variants (default: 15/40 8/24)")
    p.add_argument("--json", default=None, help="also write the rows as JSON here")
    a = p.parse_args()
    sets = suite_sets(paper_test_split(), count=a.count)
    rt = CurveRuntime.load(a.model_dir, sessions=SessionConfig(intra_op_threads=1), cache_bytes=0)
    kept = reader.LEARNED_NATURAL_STEPS
    runs = [(f"learned {s}", s, LEARNED) for s in a.steps] + [("search 15/40", "15/40", SEARCH)]
    out: dict[str, dict[str, float]] = {}
    for label, steps, fields in runs:
        scout, total = (int(x) for x in steps.split("/"))
        reader.LEARNED_NATURAL_STEPS = (scout, total)
        start = time.perf_counter()
        report = run_suite(rt, sets, **fields)
        out[label] = {"seconds": time.perf_counter() - start, **{k: v["rel_rmse_mean"] for k, v in report.items()}}
    reader.LEARNED_NATURAL_STEPS = kept
    labels = list(out)
    print("| set | " + " | ".join(labels) + " |\n|---|" + "---|" * len(labels))
    for name in sets:
        print(f"| {name} | " + " | ".join(f"{100 * out[k][name]:.4f}" for k in labels) + " |")
    print("| whole suite, seconds | " + " | ".join(f"{out[k]['seconds']:.1f}" for k in labels) + " |")
    if a.json:
        with open(a.json, "w") as f:
            json.dump(out, f, indent=1)


if __name__ == "__main__":
    main()
