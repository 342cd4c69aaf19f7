"""What fitting steps (the request option `refine`, inference/fitting.py) buy and what they cost, through the service's
runtime exactly as a request runs them.

    .venv/bin/python scripts/refine_tradeoff.py --model-dir models --count 50 --steps 0 3 5 10 20

For sets of the family suite (training/suite.py) — the paper's test curves at parameter and at arc-length spacing and
rotated, the held-out families, real airfoils where data/ has them — it prints the mean relative RMSE (RMSE over the
input's own points ÷ its bounding-box diagonal) at each number of steps, the ratio of the arc-length-spaced paper
curves' error to the parameter-spaced ones', and the time per curve as a multiple of a plain reconstruction's
(all sets, one run, one thread: these machines are noisy, so compare ratios, not seconds). With --figure, a PNG:
the error per set against the steps, and the leading edge of the first real airfoil, plain and refined. With
--basins, how much the start of the fit matters: the arc-length-spaced paper curves fitted from encodings of the same
curves respaced part of the way towards the B-spline parameter they were drawn at. With --interpolation, sweeps of
7 curves between pairs of paper curves (the second of each pair spaced by arc length), plain and refined: the interior
curves' roughness and self-intersection, and how far the first end is from its input.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path
from typing import Any

import numpy as np

from curve_vae.geometry import arc_fractions, closest_params, evaluate_bspline, self_intersects, smoothness
from curve_vae.inference import fitting
from curve_vae.inference.reading import Reading
from curve_vae.inference.runtime import CurveRuntime
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
    p.add_argument("--figure", type=Path, default=None, help="also write the figure here (PNG)")
    p.add_argument("--basins", action="store_true", help="also measure where the arc-length fit starts (see above)")
    p.add_argument("--interpolation", action="store_true", help="also measure sweeps between refined curves")
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
            out = rt.reconstruct(curves, Reading(refine=steps)).curves
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
    print("of which the matching alone (each input point to its closest point on the plain reconstruction, 0 steps):")
    for name, curves in sets.items():
        print(f"  {name:28s}{100 * matched_only(rt, curves):8.3f}%")
    if a.figure:
        plot(rt, sets, errors, a.steps, a.figure)
    if a.basins:
        basins(rt, sets["paper"], sets["paper, arc-length spacing"], max(a.steps))
    if a.interpolation:
        interpolation(rt, sets["paper"], sets["paper, arc-length spacing"], a.steps)


def interpolation(rt: Any, param: list[np.ndarray], arc: list[np.ndarray], steps: list[int]) -> None:
    """Sweeps from paper curve 2k to the arc-length-spaced paper curve 2k+1, 7 curves each, at each number of steps."""
    w = np.stack([np.linspace(1, 0, 7), np.linspace(0, 1, 7)], 1)
    pairs = [(param[2 * k], arc[2 * k + 1]) for k in range(len(param) // 2)]
    print(f"sweeps between {len(pairs)} pairs (7 curves each; interior: the 5 between the ends):")
    for n in steps:
        rough, cross, first = [], [], []
        for a, b in pairs:
            out = rt.interpolate([a, b], w, Reading(refine=n)).curves
            rough += [smoothness(c)["roughness"] for c in out[1:-1]]
            cross += [bool(self_intersects(c)) for c in out[1:-1]]
            first.append(relative_rmse([a], [out[0]])[0])
        print(
            f"  refine {n:2d}: interior roughness {np.mean(rough):.3f}°, crossing {100 * np.mean(cross):.1f}%; "
            f"first end {100 * np.mean(first):.3f}% from its input"
        )


def matched_only(rt: Any, curves: list[np.ndarray]) -> float:
    """Mean relative RMSE of the plain reconstructions with each input point at its closest point on them: what
    refine's matching gives before any step (model plane: the frames are similarities, the ratio is the same)."""
    prep = rt.prepare(curves)  # a model placed closest: each row's feet are the points' matches
    targets = [f.to_model(c, rt.model_size) for f, c in zip(prep.frames, curves)]
    fits = [evaluate_bspline(r.ctrl, r.feet) for r in prep.rows]
    return float(relative_rmse(targets, fits).mean())


def basins(rt: Any, param: list[np.ndarray], arc: list[np.ndarray], steps: int) -> None:
    """The arc-length-spaced paper curves' points, fitted from encodings of the same curves respaced part of the way
    from arc length (alpha 0) to the B-spline parameter they were drawn at (alpha 1); each fit measured from the
    arc-length-spaced points to their closest points on it."""
    print(f"arc-length-spaced paper curves, refine {steps}, the fit started from the curve respaced towards its")
    print("B-spline parameter (alpha 0: arc length, as posted; 1: the parameter):")
    even = np.linspace(0.0, 1.0, len(param[0]))
    for alpha in (0.0, 0.25, 0.5, 0.75, 1.0):
        starts = []
        for c in param:  # c: the curve at even parameters; its arc-length samples sit at these parameters
            u = (1 - alpha) * np.interp(even, arc_fractions(c), even) + alpha * even
            starts.append(np.stack([np.interp(u, even, c[:, 0]), np.interp(u, even, c[:, 1])], 1))
        splines = rt.reconstruct(starts, Reading(refine=steps)).splines
        fits = []
        for sp, points in zip(splines, arc):
            u = closest_params(sp.control_points, points, np.full(len(points), 0.5), window=1.0)
            fits.append(evaluate_bspline(sp.control_points, u))
        print(f"  alpha {alpha:4.2f}: {100 * relative_rmse(arc, fits).mean():.3f}%")


def plot(rt: Any, sets: dict[str, list], errors: dict[int, dict[str, float]], steps: list[int], path: Path) -> None:
    from curve_vae.training.figures import pyplot, save_figure

    plt = pyplot()
    fig, (left, right) = plt.subplots(1, 2, figsize=(10, 4))
    for name in sets:
        left.plot(steps, [100 * errors[s][name] for s in steps], "o-", ms=3, label=name)
    left.set(yscale="log", xlabel="refine (fitting steps)", ylabel="mean relative RMSE (of the diagonal)")
    left.grid(alpha=0.3, which="both")
    from matplotlib.ticker import FuncFormatter, NullFormatter

    left.yaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}%"))
    left.yaxis.set_minor_formatter(NullFormatter())
    shown = [100 * e for row in errors.values() for e in row.values()]
    left.set_yticks(
        [t for t in (0.01, 0.02, 0.05, 0.1, 0.2, 0.5, 1.0, 2.0) if min(shown) / 1.3 <= t <= max(shown) * 1.3]
    )
    left.legend(fontsize=7)
    real = [n for n in sets if n.startswith("airfoils")]
    curve = sets[real[0] if real else "superellipse"][0]
    edge = curve[np.argmin(curve[:, 0])]
    span = 0.04 * np.ptp(curve[:, 0])
    near = np.abs(curve - edge).max(axis=1) < span
    right.plot(*curve[near].T, "o", color="0.5", ms=3, label="input points")
    for n, colour in ((0, "tab:red"), (max(steps), "tab:blue")):
        out = rt.reconstruct([curve], Reading(refine=n), n_points=2000).curves
        o = out[0][np.abs(out[0] - edge).max(axis=1) < span]
        right.plot(*o.T, "-", color=colour, lw=1.2, label=f"refine {n}")
    right.set(aspect="equal", title="leading edge of a real airfoil (UIUC)" if real else "a superellipse")
    right.legend(fontsize=7)
    fig.tight_layout()
    save_figure(fig, path)


if __name__ == "__main__":
    main()
