"""Pose candidates measured side by side: accuracy on the family suite and cost, for a model directory.

    .venv/bin/python scripts/pose_candidates.py --model-dir models --count 100 --out runs/pose_candidates.json

Rows: pose "as_is" (the curve as oriented), and pose "auto" with 1 or 3 chord directions, with and without
the reversed-and-mirrored twin of each (the shipped setting is 3 chords with twins: 6 candidates). Each
row reports the mean relative RMSE of every suite set and the wall time of the whole suite relative to
"as_is", measured in one run (ratios only: this machine is noisy).
"""

from __future__ import annotations

import argparse
import functools
import json
import time
from pathlib import Path

import curve_vae.inference.runtime as rt
from curve_vae.geometry import frame as geometry_frame
from curve_vae.training.data import DataConfig, generate_curves
from curve_vae.training.suite import run_suite, suite_sets

ROWS = [  # label, pose, chord directions, twins
    ("as is", "as_is", 1, False),
    ("auto, 1 chord", "auto", 1, False),
    ("auto, 1 chord + twin", "auto", 1, True),
    ("auto, 3 chords", "auto", 3, False),
    ("auto, 3 chords + twins (shipped)", "auto", 3, True),
]


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--model-dir", default="models")
    p.add_argument("--count", type=int, default=100, help="curves per suite set")
    p.add_argument("--spacing", default="parameter", choices=["parameter", "arc_length"])
    p.add_argument("--out", default=None, help="also write the table as JSON here")
    a = p.parse_args()
    cfg = DataConfig()
    test = generate_curves(cfg.n_train + cfg.n_val + cfg.n_test, cfg.seed)[0][-cfg.n_test :]  # the paper's test split
    runtime = rt.CurveRuntime.load(a.model_dir, providers="cpu")
    chords, candidates = rt.POSE_CHORD_COUNT, rt.pose_frames
    results, base = {}, None
    suite = suite_sets(test, a.count)
    try:
        for label, pose, n_chords, twins in ROWS:
            rt.POSE_CHORD_COUNT = n_chords
            rt.pose_frames = functools.partial(geometry_frame.pose_frames, flips=twins)
            t0 = time.perf_counter()
            report = run_suite(runtime, suite, pose=pose, spacing=a.spacing)
            seconds = time.perf_counter() - t0
            base = base or seconds
            results[label] = {"time_vs_as_is": seconds / base, **{k: v["rel_rmse_mean"] for k, v in report.items()}}
    finally:
        rt.POSE_CHORD_COUNT, rt.pose_frames = chords, candidates
    sets = [k for k in next(iter(results.values())) if k != "time_vs_as_is"]
    print(f"{'set':28s} " + " ".join(f"{label[:16]:>16s}" for label in results))
    for s in sets:
        print(f"{s:28s} " + " ".join(f"{100 * results[label][s]:15.2f}%" for label in results))
    print(f"{'time vs as is':28s} " + " ".join(f"{results[label]['time_vs_as_is']:15.2f}×" for label in results))
    if a.out:
        Path(a.out).parent.mkdir(parents=True, exist_ok=True)
        Path(a.out).write_text(json.dumps(results, indent=2) + "\n")


if __name__ == "__main__":
    main()
