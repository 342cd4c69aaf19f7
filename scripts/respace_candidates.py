"""Re-encoding each curve respaced the way its reconstruction parametrises it: what it would give as a second candidate.

    .venv/bin/python scripts/respace_candidates.py --model-dir models --count 60

With closest placement, each input point sits at a parameter of the decoded spline (its foot). Respacing the input so
that its points fall at the spline's even parameters (the input polyline read at the feet's parameters), encoding that
and placing the points again gives a second reconstruction. Per suite set: the relative RMSE of the reconstruction as
served ("once"), of the respaced one ("respaced", model plane), and of the closer of the two per curve ("best of"),
which a service could pick without ground truth as it picks poses. Not built into the service (RESULTS.md says why).
"""

from __future__ import annotations

import argparse
import dataclasses

import numpy as np

from curve_vae.geometry import evaluate_bspline
from curve_vae.inference.runtime import CurveRuntime
from curve_vae.training.suite import paper_test_split, suite_sets

SETS = [
    "paper",
    "paper, arc-length spacing",
    "polygon",
    "spiral",
    "naca",
    "superellipse",
    "stroke",
    "lissajous",
    "airfoils (UIUC)",
]


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--model-dir", default="models")
    p.add_argument("--count", type=int, default=60, help="curves per suite set")
    a = p.parse_args()
    sets = suite_sets(paper_test_split(), count=a.count)
    rt = CurveRuntime.load(a.model_dir, providers="cpu", intra_op_threads=1)
    rt.closest_placement = True
    grid = np.linspace(0.0, 1.0, rt.n_points)
    print("| set | once | respaced | best of |\n|---|---|---|---|")
    for name in SETS:
        if name not in sets:
            continue
        curves = sets[name][1]
        prep = rt.prepare(curves)
        errors = []
        for _ in range(2):
            rows, err = [], []
            for i in range(len(curves)):
                target = prep.frames[i].to_model(prep.inputs[i], rt.model_size)
                u = np.maximum.accumulate(prep.feet[i]) + np.arange(len(target)) * 1e-12  # strictly increasing
                placed = evaluate_bspline(prep.ctrl[i].astype(np.float64), prep.feet[i])
                err.append(np.sqrt(((placed - target) ** 2).sum(-1).mean()) / np.hypot(*np.ptp(target, axis=0)))
                rows.append(np.stack([np.interp(grid, u, target[:, 0]), np.interp(grid, u, target[:, 1])], axis=1))
            errors.append(np.array(err))
            batch = np.stack(rows).astype(np.float32)
            mean, log_var = rt.graphs.encode(batch)
            prep = dataclasses.replace(
                prep, model=batch, mean=mean, log_var=log_var, decoded=None, ctrl=None, params=None, feet=None
            )
            prep = rt._refined(prep, 0)
        once, respaced = errors
        best = np.minimum(once, respaced)
        print(f"| {name} | {once.mean():.3%} | {respaced.mean():.3%} | {best.mean():.3%} |", flush=True)


if __name__ == "__main__":
    main()
