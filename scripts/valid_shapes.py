"""Whether answers are valid shapes and how close they come: per set, default and `"refine": 2` reconstructions, the
in-betweens of pairs, and seeded augmentation batches.

    .venv/bin/python scripts/valid_shapes.py [--count 200] [--pairs 50] [--sets airfoils paper] [--json out.json]

Per set (scripts/paired_readings.py's: the family suite, closed outlines, the analytic shapes): the mean relative RMSE
and the mean and largest "worst point" (largest distance ÷ bounding-box diagonal), and the share of answers that
cross themselves where the input does not. In-betweens: consecutive pairs of a set read together, 7 steps, the five
inner curves. Augmentation: 200 curves from 8 seeds, pair and triplet, seed 0. One intra-op thread, no cache.
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

from curve_vae.geometry import closeness, self_intersects  # noqa: E402
from curve_vae.inference.reading import Reading  # noqa: E402
from curve_vae.inference.runtime import CurveRuntime  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))
from paired_readings import curve_sets  # noqa: E402

STEPS = 7
AUGMENT = 200
SEEDS = 8


def crossing(inputs: list[np.ndarray], outputs: list[np.ndarray]) -> float:
    """The share of outputs that cross themselves where their input does not."""
    return float(np.mean([bool(self_intersects(o)) and not self_intersects(c) for c, o in zip(inputs, outputs)]))


def reconstructions(rt: CurveRuntime, curves: list[np.ndarray], refine: int) -> dict[str, float]:
    start = time.process_time()
    out = rt.reconstruct(curves, Reading(refine=refine)).curves
    seconds = time.process_time() - start
    rms, worst, _ = closeness(curves, out)
    return {
        "rms": float(100 * rms.mean()),
        "worst_mean": float(100 * worst.mean()),
        "worst_max": float(100 * worst.max()),
        "crossing": crossing(curves, out),
        "ms_per_curve": 1000 * seconds / len(curves),
    }


def in_betweens(rt: CurveRuntime, curves: list[np.ndarray], pairs: int) -> dict[str, float]:
    """Consecutive pairs (0, 1), (2, 3), … whose ends are valid: the share of the inner in-betweens crossing."""
    w = np.linspace(0.0, 1.0, STEPS)
    weights = np.stack([1 - w, w], axis=1)
    bad = total = skipped = 0
    for k in range(pairs):
        a, b = curves[2 * k], curves[2 * k + 1]
        if self_intersects(a) or self_intersects(b):
            skipped += 1
            continue
        made = rt.interpolate([a, b], weights).curves[1:-1]
        bad += sum(bool(self_intersects(c)) for c in made)
        total += len(made)
    return {"crossing": bad / max(total, 1), "in_betweens": total, "pairs_skipped": skipped}


def augmented(rt: CurveRuntime, seeds: list[np.ndarray], mode: str) -> dict[str, float]:
    plan = rt.plan_augment(seeds, seed=0, mode=mode)
    made = rt.augment(plan, 0, AUGMENT)
    return {
        "crossing": float(np.mean([bool(self_intersects(c)) for c in made.curves])),
        "redrawn": int(getattr(made, "redrawn", 0)),
    }


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--model-dir", default="models")
    p.add_argument("--count", type=int, default=200, help="curves per set (default: 200)")
    p.add_argument("--pairs", type=int, default=50, help="pairs per set for in-betweens (default: 50)")
    p.add_argument("--sets", nargs="*", default=[], help="only the sets whose names contain these words")
    p.add_argument("--skip-refine", action="store_true", help="default reconstructions alone")
    p.add_argument("--json", default="", help="also write the rows here")
    a = p.parse_args()
    rt = CurveRuntime.load(a.model_dir, intra_op_threads=1, cache_bytes=0)
    sets = curve_sets(a.count)
    if a.sets:
        sets = {n: c for n, c in sets.items() if any(w in n for w in a.sets)}
    rows: dict[str, dict[str, object]] = {}
    print("| set | default: RMS, worst point (mean / max), crossing | refine 2: the same | in-betweens crossing |")
    print("|---|---|---|---|")
    for name, curves in sets.items():
        row: dict[str, object] = {"default": reconstructions(rt, curves, 0)}
        if not a.skip_refine:
            row["refine 2"] = reconstructions(rt, curves, 2)
        if name in ("paper", "airfoils (UIUC)", "naca"):
            row["in-betweens"] = in_betweens(rt, curves, min(a.pairs, len(curves) // 2))
        rows[name] = row

        def cell(r: object) -> str:
            if not isinstance(r, dict):
                return ""
            if "rms" not in r:
                return f"{100 * r['crossing']:.1f}% of {r['in_betweens']}"
            return f"{r['rms']:.3f}%, {r['worst_mean']:.3f} / {r['worst_max']:.2f}%, {100 * r['crossing']:.1f}%"

        print(
            f"| {name} | {cell(row['default'])} | {cell(row.get('refine 2'))} | {cell(row.get('in-betweens'))} |",
            flush=True,
        )
    for name in ("paper", "airfoils (UIUC)"):
        if name in sets:
            seeds = [c for c in sets[name] if not self_intersects(c)][:SEEDS]
            for mode in ("pair", "triplet"):
                r = rows.setdefault(f"augment {mode}, {name} seeds", {})["augment"] = augmented(rt, seeds, mode)
                print(
                    f"augment {mode} from {SEEDS} {name}: {100 * r['crossing']:.1f}% crossing, {r['redrawn']} redrawn"
                )
    if a.json:
        Path(a.json).write_text(json.dumps(rows, indent=2))


if __name__ == "__main__":
    main()
