"""How close each reading brings users' curves back, and what it costs: the table of docs/RESULTS.md "Readings".

Sets (one run, seeded): 40 paper test curves as drawn; 40 resampled by arc length to 50 and to 161 points, turned,
mirrored and reversed at random; 40 moved as drawn; 20 real UIUC airfoils (none of them labelled for the ranker);
10 analytic shapes, moved. Each cell: mean relative RMSE (% of the bounding-box diagonal, at the curve's own
points) and, last, milliseconds of one core per curve (one onnxruntime thread, encoding cache off): whole sets at
once, and the paper's curves as drawn one request each.

    .venv/bin/python scripts/reading_table.py [--model-dir models] [--json out.json] [--morphs 40]

`--morphs N`: also the morph suite (training/morphs.py: N pairs of paper curves drawn in one pose, swept in 7 steps)
with the search and the learned reading, as a Markdown table: how far in-betweens turn and drift.
"""

from __future__ import annotations

import argparse
import json
import os
import time

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")  # one core, as the service's inference threads run

import numpy as np  # noqa: E402

from curve_vae.geometry.frame import resample  # noqa: E402
from curve_vae.inference.reading import Reading  # noqa: E402
from curve_vae.inference.runtime import CurveRuntime  # noqa: E402
from curve_vae.training.suite import AIRFOIL_WHEEL, paper_test_split, random_moves, relative_rmse  # noqa: E402

READINGS = {
    "search (6 poses × spacings)": Reading(pose="search", spacing="search"),
    "learned (ranker, 2 encoded)": Reading(pose="learned", spacing="search"),
    "canonical, as given (1 encoded)": Reading(pose="canonical", spacing="parameter"),
    "learned + refine 2": Reading(pose="learned", spacing="search", refine=2),
    "as given, upright (1 encoded)": Reading(pose="as_is", spacing="parameter"),
}


def analytic() -> list[np.ndarray]:
    """Ten analytic shapes at 120 points even in their own parameter."""
    t = np.linspace(0, 1, 120)
    a, h = 2 * np.pi * t, np.pi * t
    return [
        np.c_[np.cos(1.5 * h), np.sin(1.5 * h)],  # three quarters of a circle
        np.c_[2 * np.cos(a), np.sin(a)],  # an ellipse
        np.c_[4 * t, np.sin(3 * np.pi * t)],  # a sine wave
        np.c_[(0.3 + t) * np.cos(3 * h), (0.3 + t) * np.sin(3 * h)],  # a spiral
        np.c_[2 * t - 1, (2 * t - 1) ** 2],  # a parabola
        np.c_[np.sign(np.cos(a)) * np.abs(np.cos(a)) ** 0.5, np.sign(np.sin(a)) * np.abs(np.sin(a)) ** 0.5],
        np.c_[np.sin(2 * h), np.sin(3 * h)],  # a Lissajous figure
        np.c_[(1 - np.cos(a)) * np.cos(a), (1 - np.cos(a)) * np.sin(a)],  # a cardioid
        np.c_[3 * t, np.tanh(6 * (t - 0.5))],  # a step
        np.c_[np.cos(h), np.sin(h)],  # a half circle
    ]


def table_sets() -> dict[str, list[np.ndarray]]:
    from curve_vae.training.airfoils import load_airfoils

    rng = np.random.default_rng(11)
    paper = [np.asarray(c, np.float64) for c in paper_test_split()[:80]]
    sets = {
        "paper, as drawn": paper[:40],
        "arc length, 50 pts": random_moves([resample(c, 50) for c in paper[40:80]], rng),
        "arc length, 161 pts": random_moves([resample(c, 161) for c in paper[:40]], rng),
        "moved": random_moves(paper[40:80], rng),
        "analytic shapes": random_moves(analytic(), rng),
    }
    if AIRFOIL_WHEEL.exists():
        sets["UIUC airfoils"] = load_airfoils(AIRFOIL_WHEEL, 20, seed=5)
    return sets


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--model-dir", default="models")
    p.add_argument("--json", default="", help="also write the table here")
    p.add_argument("--readings", nargs="*", default=list(READINGS), help="rows (default: all)")
    p.add_argument("--morphs", type=int, default=0, help="pairs of the morph suite per reading (default: none)")
    a = p.parse_args()
    rt = CurveRuntime.load(a.model_dir, intra_op_threads=1, cache_bytes=0)
    sets = table_sets()
    print(f"{'reading':34s}" + "".join(f"{k:>21s}" for k in sets) + f"{'ms/curve':>10s}{'ms alone':>10s}")
    out = {}
    for name in a.readings:
        reading, row, spent, count = READINGS[name], {}, 0.0, 0
        for set_name, curves in sets.items():
            t0 = time.perf_counter()
            got = rt.reconstruct(curves, reading).curves
            spent += time.perf_counter() - t0
            count += len(curves)
            row[set_name] = float(100 * relative_rmse(curves, got).mean())
        row["ms_per_curve"] = 1000 * spent / count
        alone = sets["paper, as drawn"]
        t0 = time.perf_counter()
        for c in alone:
            rt.reconstruct([c], reading)
        row["ms_alone"] = 1000 * (time.perf_counter() - t0) / len(alone)
        out[name] = row
        cells = "".join(f"{row[k]:20.3f}%" for k in sets)
        print(f"{name:34s}{cells}{row['ms_per_curve']:10.1f}{row['ms_alone']:10.1f}", flush=True)
    if a.morphs:
        from curve_vae.training.morphs import format_morphs, morph_pairs, run_morphs

        swept = {k: READINGS[k] for k in list(READINGS)[:2]}  # the search and the learned reading
        out["morphs"] = run_morphs(rt, morph_pairs(paper_test_split(), a.morphs), readings=swept)
        print(format_morphs(out["morphs"]))
    if a.json:
        with open(a.json, "w") as fh:
            json.dump(out, fh, indent=2)


if __name__ == "__main__":
    main()
