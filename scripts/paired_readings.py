"""Two model directories read the same curves with default fields, curve by curve: did the second read them closer?

    .venv/bin/python scripts/paired_readings.py models runs/candidate-model [--count 200] [--json out.json]

For deciding whether a retrained part (a ranker, a spacing guesser) ships: both models read every set of the family
suite (training/suite.py), closed outlines (training.families.closed, a seed no label was drawn with) and the
reading table's ten analytic shapes, each curve's relative RMSE (% of its bounding-box diagonal) is paired, and
each set's change of the mean comes with a 95% bootstrap interval (2,000 resamples of the curves) and the share of
curves whose answer changed at all. One intra-op thread, no encoding cache.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
from pathlib import Path

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")  # one core, as the service's inference threads run

import numpy as np  # noqa: E402

from curve_vae.inference.reading import Reading  # noqa: E402
from curve_vae.inference.runtime import CurveRuntime  # noqa: E402
from curve_vae.training.families import closed, draw_family  # noqa: E402
from curve_vae.training.suite import paper_test_split, random_moves, relative_rmse, suite_sets  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))
from reading_table import analytic  # noqa: E402

#: Seed of the closed outlines measured here: the ranker's labels use seeds 1-3 (docs/TRAINING.md).
CLOSED_SEED = 4242


def curve_sets(count: int) -> dict[str, list[np.ndarray]]:
    sets = {name: curves for name, (_, curves) in suite_sets(paper_test_split(), count).items()}
    rng = np.random.default_rng(CLOSED_SEED)
    drawn = draw_family(closed, count, rng, n_points=120, model_size=None, chunk=64).astype(np.float64)
    sets["closed outlines"] = random_moves(list(drawn), rng)
    sets["analytic shapes"] = random_moves(analytic(), np.random.default_rng(11))
    return sets


def paired(before: np.ndarray, after: np.ndarray, rng: np.random.Generator) -> dict[str, float]:
    """The change of the mean relative RMSE, as a fraction of `before`'s mean, with its 95% bootstrap interval."""
    d = (after - before) / before.mean()
    boot = np.array([d[rng.integers(0, len(d), len(d))].mean() for _ in range(2000)])
    return {
        "before": float(before.mean()),
        "after": float(after.mean()),
        "change": float(d.mean()),
        "low": float(np.percentile(boot, 2.5)),
        "high": float(np.percentile(boot, 97.5)),
        "changed_curves": float(np.mean(np.abs(after - before) > 1e-9 * before.mean())),
    }


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("before", help="the reference model directory")
    p.add_argument("after", help="the model directory compared with it")
    p.add_argument("--count", type=int, default=200, help="curves per suite set and closed outlines (default: 200)")
    p.add_argument("--json", default="", help="also write the rows here")
    a = p.parse_args()
    runtimes = [CurveRuntime.load(d, intra_op_threads=1, cache_bytes=0) for d in (a.before, a.after)]
    rng = np.random.default_rng(0)
    rows = {}
    print(f"| set | {a.before} | {a.after} | change, 95% interval | curves changed |\n|---|---|---|---|---|")
    for name, curves in curve_sets(a.count).items():
        before, after = (100 * relative_rmse(curves, rt.reconstruct(curves, Reading()).curves) for rt in runtimes)
        r = rows[name] = paired(before, after, rng)
        print(
            f"| {name} | {r['before']:.4f}% | {r['after']:.4f}% | {100 * r['change']:+.1f}% "
            f"({100 * r['low']:+.1f} to {100 * r['high']:+.1f}) | {100 * r['changed_curves']:.0f}% |",
            flush=True,
        )
    if a.json:
        Path(a.json).write_text(json.dumps(rows, indent=2))


if __name__ == "__main__":
    main()
