"""Model directories side by side on the family suite, as the service serves them: error per set and cost.

    .venv/bin/python scripts/compare_models.py models/paper models --count 200 --out runs/compare.json
    .venv/bin/python scripts/compare_models.py models --readings auto canonical/parameter search/search as_is/parameter

Each model runs the whole suite (training/suite.py: the paper's test curves as drawn, at arc-length spacing and
moved; the trained families; the held-out ones; real airfoils where data/ has aerosandbox's wheel) through
`CurveRuntime.reconstruct` with each reading asked for (`--readings POSE/SPACING …`, "auto" the model's own: what a
request with default fields gets), no encoding cache, one intra-op thread. Rows: each set's mean relative RMSE per
model and reading, the arc-length ÷ parameter ratio, and the wall time of the whole suite relative to the first
column, measured in one run (ratios only: this machine is noisy). `--placement` runs each model as its manifest
says ("manifest") or with its points at the decoder's own parameters ("index") or at their closest points
("closest"), whatever its manifest says.
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

from curve_vae.inference.reading import Reading
from curve_vae.inference.runtime import CurveRuntime
from curve_vae.training.suite import paper_test_split, run_suite, suite_sets


def _reading(text: str) -> Reading:
    if text == "auto":
        return Reading()
    pose, spacing = text.split("/")
    return Reading(pose=pose, spacing=spacing)  # type: ignore[arg-type]


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("model_dirs", nargs="+", help="exported model directories (the first is the reference)")
    p.add_argument("--count", type=int, default=100, help="curves per suite set (default: 100)")
    p.add_argument("--placement", choices=["manifest", "index", "closest"], nargs="+", default=["manifest"])
    p.add_argument("--readings", nargs="+", default=["auto"], help="POSE/SPACING pairs, or auto (default: auto)")
    p.add_argument("--out", default=None, help="also write the table as JSON here")
    a = p.parse_args()
    sets = suite_sets(paper_test_split(), count=a.count)
    columns: dict[str, dict] = {}
    for model_dir in a.model_dirs:
        for placement in a.placement:
            runtime = CurveRuntime.load(model_dir, providers="cpu", intra_op_threads=1, cache_bytes=0)
            if placement != "manifest":
                runtime.closest_placement = placement == "closest"
            for text in a.readings:
                reading = runtime.reading(_reading(text))
                how = [*([] if placement == "manifest" else [placement]), f"{reading.pose}/{reading.spacing}"]
                label = f"{runtime.manifest.version} ({', '.join([model_dir, *how])})"
                start = time.perf_counter()
                report = run_suite(runtime, sets, pose=reading.pose, spacing=reading.spacing)
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
