"""What fitting steps (the request option `refine`, service/fitting.py) buy and what they cost, through the service's
runtime exactly as a request runs them.

    .venv/bin/python scripts/refine_tradeoff.py --model-dir models --count 50 --steps 0 3 5 10 20

For sets of the family suite (training/suite.py) — the paper's test curves at parameter and at arc-length spacing and
rotated, the held-out families, real airfoils where data/ has them — it prints the mean relative RMSE (RMSE over the
input's own points ÷ its bounding-box diagonal) at each number of steps, the ratio of the arc-length-spaced paper
curves' error to the parameter-spaced ones', and the time per curve as a multiple of a plain reconstruction's
(all sets, one run, one thread: these machines are noisy, so compare ratios, not seconds).
"""

from __future__ import annotations

import argparse
import time

from curve_vae.service import fitting
from curve_vae.service.runtime import CurveRuntime
from curve_vae.training.suite import paper_test_split, relative_rmse, suite_sets

SETS = ("paper", "paper, arc-length spacing", "paper, rotated")


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--model-dir", default="models")
    p.add_argument("--count", type=int, default=50, help="curves per set (default: 50)")
    p.add_argument("--steps", type=int, nargs="+", default=[0, 3, 5, 10, 20])
    p.add_argument(
        "--jacobian-every",
        type=int,
        default=fitting.JACOBIAN_EVERY,
        help=f"steps between forward-difference Jacobians (default: {fitting.JACOBIAN_EVERY}, the service's)",
    )
    a = p.parse_args()
    fitting.JACOBIAN_EVERY = a.jacobian_every
    rt = CurveRuntime.load(a.model_dir, providers="cpu", intra_op_threads=1)
    every = suite_sets(paper_test_split(), a.count)
    sets = {k: c for k, (kind, c) in every.items() if k in SETS or kind in ("held out", "real")}
    errors: dict[int, dict[str, float]] = {}
    seconds: dict[int, float] = {}
    for steps in a.steps:
        errors[steps], seconds[steps] = {}, 0.0
        for name, curves in sets.items():
            start = time.perf_counter()
            out, _ = rt.reconstruct(curves, refine=steps)
            seconds[steps] += time.perf_counter() - start
            errors[steps][name] = float(relative_rmse(curves, out).mean())
    base = seconds[a.steps[0]]
    print(f"{'set':28s}" + "".join(f"{f'refine {s}':>11s}" for s in a.steps))
    for name in sets:
        print(f"{name:28s}" + "".join(f"{100 * errors[s][name]:10.3f}%" for s in a.steps))
    ratio = [errors[s]["paper, arc-length spacing"] / errors[s]["paper"] for s in a.steps]
    print(f"{'arc-length ÷ parameter':28s}" + "".join(f"{r:10.2f}×" for r in ratio))
    n = sum(len(c) for c in sets.values())
    print(f"{'time per curve (× the first)':28s}" + "".join(f"{seconds[s] / base:10.1f}×" for s in a.steps))
    print(f"({n} curves per column; the first column: {1000 * base / n:.1f} ms per curve on this machine)")
    print("mean relative RMSE per set (RMSE ÷ bounding-box diagonal, at the input's own points)")


if __name__ == "__main__":
    main()
