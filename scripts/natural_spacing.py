"""How near the natural readings (`geometry.natural_readings`) bring the paper's curves drawn by arc length to their
own spacing, evenly in their B-spline parameter, and what the fit costs.

    .venv/bin/python scripts/natural_spacing.py --count 200

Per curve of the paper's test split (161 points, drawn evenly in the parameter), resampled evenly by arc length:
the relative RMSE, point by point, between its 161 even-parameter samples and (a) the arc-length points as drawn,
(b) the curve read at even steps of its natural parameters, from the closest fit and from the fit that started at
the arc-length fractions (the second reading where the two differ). Prints medians, means, the share of curves
read closer than drawn and read at their own spacing (within 0.1% of the diagonal), and milliseconds per
`natural_readings` call (one run, one thread: a ratio to compare, not a promise).

With `--model-dir` it also measures where a model's arc-length gap sits (closest placement, pose "auto"): the
arc-length points' distance (each to its closest point, RMS ÷ diagonal) to their own reconstruction and to the
reconstruction of the same curves spaced by parameter (their twins), the parameter-spaced points' to theirs, and
the arc-length points' distance to the true B-spline (the suite interpolates them linearly between the 161 samples).

    .venv/bin/python scripts/natural_spacing.py --count 100 --model-dir models
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from curve_vae.geometry import (
    arc_fractions,
    closeness,
    closest_squared_distances,
    diagonal,
    natural_readings,
    resample,
    to_model_plane,
)
from curve_vae.geometry.bspline import basis_and_slope
from curve_vae.training.suite import paper_test_split


def gap(model_dir: str, even: np.ndarray, drawn: list[np.ndarray]) -> None:
    """Where the arc-length gap of a model sits: its encoder's reading, or its decoder's reach."""
    from curve_vae.inference.runtime import CurveRuntime
    from curve_vae.training.data import DataConfig, generate_curves

    rt = CurveRuntime.load(model_dir, providers="cpu", intra_op_threads=1)
    rt.closest_placement = True
    params = list(even)
    own = rt.reconstruct(drawn, n_points=3201).curves
    twins = rt.reconstruct(params, n_points=3201).curves
    diag = diagonal(even)

    def dist(points: list[np.ndarray], lines: list[np.ndarray]) -> float:
        return float(np.mean([np.sqrt(closest_squared_distances(p, q).mean()) for p, q in zip(points, lines)] / diag))

    cfg = DataConfig()  # the test split again, sampled 10× as densely: the true curves, to 0.001% of the diagonal
    total = cfg.n_train + cfg.n_val + cfg.n_test
    dense = generate_curves(total, cfg.seed, n_points=1601)[0][-cfg.n_test :][: len(even)].astype(np.float64)
    print(
        f"{model_dir}: parameter-spaced points to their reconstruction {dist(params, twins):.3%}; arc-length points "
        f"to theirs {dist(drawn, own):.3%}, to their twins' {dist(drawn, twins):.3%}; arc-length points to the true "
        f"curve {dist(drawn, list(dense)):.4%}"
    )


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--count", type=int, default=200)
    p.add_argument("--steps", type=int, nargs="+", default=[40], help="LM steps of the fit (natural_readings steps)")
    p.add_argument("--model-dir", nargs="*", default=[], help="also measure where these models' arc-length gap sits")
    a = p.parse_args()
    even = paper_test_split()[: a.count].astype(np.float64)
    drawn = [resample(c, len(c)) for c in even]

    def rel(x: np.ndarray, ref: np.ndarray) -> float:
        return float(closeness([ref], [x])[0][0])

    def fit_rms(points: np.ndarray, u: np.ndarray) -> float:
        """RMS distance ÷ diagonal from the points to the least-squares 10-point spline at their parameters u."""
        basis, _ = basis_and_slope(u, 10)
        fitted = basis @ np.linalg.lstsq(basis, points, rcond=None)[0]
        return float(closeness([points], [fitted])[0][0])

    as_drawn = np.array([rel(d, c) for d, c in zip(drawn, even)])
    print(f"as drawn: median {np.median(as_drawn):.2%}, mean {as_drawn.mean():.2%}")
    # each drawn point's own B-spline parameter: where its arc length falls along the even-parameter samples
    own = [np.interp(np.linspace(0.0, 1.0, len(c)), arc_fractions(c), np.linspace(0.0, 1.0, len(c))) for c in even]
    print(
        f"the spline fitted at their own parameters: {np.median([fit_rms(d, u) for d, u in zip(drawn, own)]):.4%} "
        "of the diagonal from the points (median)"
    )
    for steps in a.steps:
        start = time.perf_counter()
        readings = [natural_readings(d, steps=steps) for d in drawn]
        ms = (time.perf_counter() - start) / len(drawn) * 1e3
        for label, pick in (("closest fit", 0), ("fit from arc length", -1)):
            read = np.array(
                [
                    rel(
                        to_model_plane(d, None, model_size=1.0, n_points=len(c), spacing="natural", natural=r[pick])[0],
                        c,
                    )
                    for d, r, c in zip(drawn, readings, even)
                ]
            )
            rms = np.median([fit_rms(d, r[pick]) for d, r in zip(drawn, readings)])
            print(
                f"natural, {steps} steps, {label}: median {np.median(read):.2%}, mean {read.mean():.2%}, "
                f"closer than drawn {np.mean(read < as_drawn):.0%}, at their own spacing (within 0.1%) "
                f"{np.mean(read < 1e-3):.0%}; its spline {rms:.4%} from the points (median)"
            )
        print(f"  {ms:.1f} ms per curve for both; the two differ for {np.mean([len(r) == 2 for r in readings]):.0%}")
    for model_dir in a.model_dir:
        gap(model_dir, even, drawn)


if __name__ == "__main__":
    main()
