"""How often the natural fit finds the paper's curves' own parameters, from the spacing guesser's guess and from the
fit's nine starts, and what each costs.

    .venv/bin/python scripts/guessed_spacing.py [--model-dir models] [--count 200]

The paper's curves (random_control_points, seed 77) drawn exactly at 161 points evenly spaced along their length,
where each point's own parameter is known: per way of fitting, the median and 90th percentile of the RMS distance
between the parameters found (the closest reading) and the curve's own, the share within 0.001 of them, and the
milliseconds per curve of `geometry.natural_readings_of` over the whole batch (one run, one thread: a ratio to
compare, not a promise). docs/RESULTS.md "The spacing guesser" quotes its output.
"""

from __future__ import annotations

import argparse
import os
import time

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # noqa: E402

from curve_vae.geometry import arc_length_params, natural_readings_of, random_control_points  # noqa: E402
from curve_vae.geometry.bspline import evaluate_bspline  # noqa: E402
from curve_vae.inference.runtime import CurveRuntime  # noqa: E402


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--model-dir", default="models", help="the model whose guesser guesses (default: models)")
    p.add_argument("--count", type=int, default=200, help="curves (default: 200)")
    a = p.parse_args()
    spacer = CurveRuntime.load(a.model_dir, providers="cpu", intra_op_threads=1, cache_bytes=0).reader.spacer
    assert spacer is not None, f"{a.model_dir} has no spacing guesser"
    ctrl = random_control_points(np.random.default_rng(77), a.count)
    own = [arc_length_params(c, 161) for c in ctrl]
    drawn = [evaluate_bspline(c, u) for c, u in zip(ctrl, own)]
    ways = {
        "the guess alone": {"guess": spacer.guesses, "scout": 0, "steps": 0},
        "from the guess, 4/8 steps": {"guess": spacer.guesses, "scout": 4, "steps": 8},
        "from the guess, 6/12 steps": {"guess": spacer.guesses, "scout": 6, "steps": 12},
        "nine starts, 8/24 steps": {"scout": 8, "steps": 24},
        "nine starts, 15/40 steps (the search's)": {"scout": 15, "steps": 40},
    }
    print("| fit | median RMS off | 90th percentile | within 0.001 | ms per curve |\n|---|---|---|---|---|")
    for label, fit in ways.items():
        start = time.perf_counter()
        readings = natural_readings_of(drawn, **fit)
        ms = (time.perf_counter() - start) / len(drawn) * 1e3
        off = np.array([np.sqrt(((r[0] - u) ** 2).mean()) for r, u in zip(readings, own)])
        print(
            f"| {label} | {np.median(off):.4f} | {np.quantile(off, 0.9):.4f} | {np.mean(off < 1e-3):.0%} | {ms:.2f} |"
        )


if __name__ == "__main__":
    main()
