"""The learned reading with and without the spacing guesser and at several natural-fit steps: the family suite per
set, beside the search.

    .venv/bin/python scripts/natural_steps.py [--count 200] [--steps 8/24] [--guessed 6/12 4/8] [--json out.json]

Each STEPS is SCOUT/TOTAL Levenberg–Marquardt steps of geometry.natural_readings_of (every start scouts SCOUT
steps, the closest and the arc-length one go on to TOTAL): `--steps` from the fit's own nine starts (the reader's
LEARNED_NATURAL_STEPS, the reading of a model without a guesser), `--guessed` from the model's spacing guesser and
the arc-length fractions (GUESSED_NATURAL_STEPS); the search runs once, with the fit's own 15/40. Rows: each suite
set's mean relative RMSE (% of the diagonal) per variant, and the whole suite's wall time. One intra-op thread, no
encoding cache. docs/RESULTS.md "The spacing guesser" is its output with the defaults.
"""

from __future__ import annotations

import argparse
import json
import os
import time

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")  # one core, as the service's inference threads run

from curve_vae.inference import reader  # noqa: E402
from curve_vae.inference.model.sessions import SessionConfig  # noqa: E402
from curve_vae.inference.runtime import CurveRuntime  # noqa: E402
from curve_vae.training.suite import paper_test_split, run_suite, suite_sets  # noqa: E402

SEARCH = {"pose": "search", "spacing": "search"}
LEARNED = {"pose": "learned", "spacing": "search"}


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--model-dir", default="models", help="the model (default: models)")
    p.add_argument("--count", type=int, default=200, help="curves per suite set (default: 200)")
    p.add_argument("--steps", nargs="*", default=["8/24"], help="SCOUT/TOTAL without the guesser (default: 8/24)")
    p.add_argument(
        "--guessed", nargs="*", default=["6/12", "4/8"], help="SCOUT/TOTAL from the guesser (default: 6/12 4/8)"
    )
    p.add_argument("--json", default=None, help="also write the rows as JSON here")
    a = p.parse_args()
    sets = suite_sets(paper_test_split(), count=a.count)
    rt = CurveRuntime.load(a.model_dir, sessions=SessionConfig(intra_op_threads=1), cache_bytes=0)
    spacer = rt.reader.spacer
    if a.guessed and spacer is None:
        p.error(f"{a.model_dir} has no spacing guesser: --guessed needs one")
    kept = reader.LEARNED_NATURAL_STEPS, reader.GUESSED_NATURAL_STEPS
    runs = [(f"learned {s}", s, None) for s in a.steps] + [(f"guessed {s}", s, spacer) for s in a.guessed]
    out: dict[str, dict[str, float]] = {}
    for label, steps, guesser in runs:
        scout, total = (int(x) for x in steps.split("/"))
        reader.LEARNED_NATURAL_STEPS = reader.GUESSED_NATURAL_STEPS = (scout, total)
        rt.reader.spacer = guesser
        start = time.perf_counter()
        report = run_suite(rt, sets, **LEARNED)
        out[label] = {"seconds": time.perf_counter() - start, **{k: v["rel_rmse_mean"] for k, v in report.items()}}
        print(f"{label}: {out[label]['seconds']:.1f} s", flush=True)
    reader.LEARNED_NATURAL_STEPS, reader.GUESSED_NATURAL_STEPS = kept
    rt.reader.spacer = spacer
    start = time.perf_counter()
    report = run_suite(rt, sets, **SEARCH)
    out["search 15/40"] = {"seconds": time.perf_counter() - start, **{k: v["rel_rmse_mean"] for k, v in report.items()}}
    labels = list(out)
    search = out["search 15/40"]
    print("| set | " + " | ".join(labels) + " |\n|---|" + "---|" * len(labels))
    for name in sets:
        print(
            f"| {name} | "
            + " | ".join(f"{100 * out[k][name]:.4f} ({out[k][name] / search[name]:.2f}×)" for k in labels)
            + " |"
        )
    print("| whole suite, seconds | " + " | ".join(f"{out[k]['seconds']:.1f}" for k in labels) + " |")
    if a.json:
        with open(a.json, "w") as f:
            json.dump(out, f, indent=1)


if __name__ == "__main__":
    main()
