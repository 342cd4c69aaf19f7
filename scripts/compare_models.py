"""Model directories side by side on the family suite, as the service serves them: error per set and cost.

    .venv/bin/python scripts/compare_models.py models/paper models --count 200 --out runs/compare.json

Each model runs the whole suite (training/suite.py: the paper's test curves as drawn, at arc-length spacing and
moved; the trained families; the held-out ones; real airfoils) through `CurveRuntime.reconstruct` with the default
request (frame and pose "auto", spacing "parameter" unless `--spacing` says otherwise, no refine), one intra-op
thread. Rows: each set's mean relative RMSE per model, the arc-length ÷ parameter ratio, and the wall time of the
whole suite relative to the first model, measured in one run (ratios only: this machine is noisy).

`--placement` runs each model as its manifest says ("manifest"), or with its points at the decoder's own parameters
("index") or at their closest points on the decoded spline, poses picked so too ("closest"), whatever its manifest
says: what the placement alone gives, apart from what training on closest points gives. `--spacing` runs each with
each reading of the curves (the request's `spacing`: "parameter", "arc_length", "natural" or "auto"):

    .venv/bin/python scripts/compare_models.py models --count 200 --spacing parameter arc_length natural auto

`--natural-steps N` fits the natural readings (`geometry.natural_readings`) with N Levenberg–Marquardt steps instead
of the service's 40; `--one-natural` has spacing "auto" try the closest fit's reading only, not also the fit from the
arc-length fractions.
"""

from __future__ import annotations

import argparse
import functools
import json
import time
from pathlib import Path

from curve_vae.geometry import natural_params, natural_readings
from curve_vae.inference.runtime import CurveRuntime
from curve_vae.training.suite import paper_test_split, run_suite, suite_sets


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("model_dirs", nargs="+", help="exported model directories (the first is the reference)")
    p.add_argument("--count", type=int, default=100, help="curves per suite set")
    p.add_argument("--placement", choices=["manifest", "index", "closest"], nargs="+", default=["manifest"])
    p.add_argument(
        "--spacing", choices=["parameter", "arc_length", "natural", "auto"], nargs="+", default=["parameter"]
    )
    p.add_argument("--out", default=None, help="also write the table as JSON here")
    p.add_argument("--natural-steps", type=int, default=None, help="steps of the natural fit (default: the service's)")
    p.add_argument("--one-natural", action="store_true", help='spacing "auto" tries the closest natural fit only')
    a = p.parse_args()
    from curve_vae.inference import runtime as runtime_module

    steps = {} if a.natural_steps is None else {"steps": a.natural_steps}
    runtime_module.natural_params = functools.partial(natural_params, **steps)
    runtime_module.natural_readings = (
        (lambda pts: natural_readings(pts, **steps)[:1])
        if a.one_natural
        else functools.partial(natural_readings, **steps)
    )
    sets = suite_sets(paper_test_split(), count=a.count)
    columns: dict[str, dict] = {}
    for model_dir in a.model_dirs:
        for placement in a.placement:
            runtime = CurveRuntime.load(model_dir, providers="cpu", intra_op_threads=1)
            if placement != "manifest":
                runtime.closest_placement = placement == "closest"
            for spacing in a.spacing:
                how = [
                    *([] if placement == "manifest" else [placement]),
                    *([] if spacing == "parameter" else [spacing]),
                ]
                label = f"{runtime.manifest['version']} ({', '.join([model_dir, *how])})"
                start = time.perf_counter()
                report = run_suite(runtime, sets, spacing=spacing)
                columns[label] = {"seconds": time.perf_counter() - start, "sets": report}
                print(f"measured {label}: {columns[label]['seconds']:.0f} s", flush=True)
    first = next(iter(columns.values()))["seconds"]
    labels = list(columns)
    print(f"\n| set | {' | '.join(labels)} |\n|---|{'---|' * len(labels)}")
    for name in sets:
        cells = [f"{columns[k]['sets'][name]['rel_rmse_mean'] * 100:.3f}%" for k in labels]
        print(f"| {name} | {' | '.join(cells)} |")
    ratio = [
        columns[k]["sets"]["paper, arc-length spacing"]["rel_rmse_mean"] / columns[k]["sets"]["paper"]["rel_rmse_mean"]
        for k in labels
    ]
    print(f"| arc-length ÷ parameter | {' | '.join(f'{r:.2f}×' for r in ratio)} |")
    times = [columns[k]["seconds"] / first for k in labels]
    print(f"| suite time vs the first | {' | '.join(f'{t:.2f}×' for t in times)} |")
    if a.out:
        Path(a.out).write_text(json.dumps({"count": a.count, "columns": columns}, indent=1, default=float))


if __name__ == "__main__":
    main()
