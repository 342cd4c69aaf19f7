"""The evaluation suite of curve families: how a model does on the curves people send, through the service's own
runtime (frames, resampling, pose), exactly as users receive it.

Sets, each measured by relative RMSE (RMSE over the input's own points ÷ its bounding-box diagonal), roughness
of the reconstruction ÷ the input's, and the share of reconstructions that cross themselves:

- the paper's test curves as generated, resampled by arc length, reversed, mirrored and rotated (any angle);
- each training family of training/families.py, fresh curves at random spacings and poses;
- HELD_OUT families, never trained on: generalisation, not memory;
- real airfoils (the UIUC database, read from aerosandbox's wheel when data/ has it).

Torch-free: it needs only a model directory.
"""

from __future__ import annotations

from functools import cache
from pathlib import Path
from typing import Any

import numpy as np

from curve_vae.geometry import closeness, resample, self_intersects, smoothness
from curve_vae.training.families import HELD_OUT, TRAIN_FAMILIES, draw_family

AIRFOIL_WHEEL = Path("data/aerosandbox-4.2.10-py3-none-any.whl")


@cache
def paper_test_split() -> np.ndarray:
    """The paper's 1,000 test curves: the test split of the default data set (seed 0), generated once a process
    (under a second; read-only, shared by the family suite, the morph suite and the figures)."""
    from curve_vae.training.data import DataConfig, generate_curves

    cfg = DataConfig()
    split = generate_curves(cfg.n_test, cfg.seed, n_points=cfg.n_points, skip=cfg.n_train + cfg.n_val)[0]
    split.flags.writeable = False
    return split


def random_moves(curves: list[np.ndarray], rng: np.random.Generator) -> list[np.ndarray]:
    """Each curve turned by a random angle, mirrored or reversed at random: a user's drawing in any pose."""
    out = []
    for c in curves:
        a = rng.uniform(0, 2 * np.pi)
        rot = np.array([[np.cos(a), np.sin(a)], [-np.sin(a), np.cos(a)]])
        c = (c * ([-1.0, 1.0] if rng.random() < 0.5 else 1.0)) @ rot
        out.append(c[::-1] if rng.random() < 0.5 else c)
    return out


def suite_sets(test_curves: np.ndarray, count: int = 200, seed: int = 2024) -> dict[str, tuple[str, list[np.ndarray]]]:
    """name -> (kind, curves): kind "paper", "trained" or "held out"/"real" families."""
    rng = np.random.default_rng(seed)
    paper = [np.asarray(c, np.float64) for c in test_curves[:count]]
    angle = rng.uniform(0, 2 * np.pi, len(paper))
    sets: dict[str, tuple[str, list[np.ndarray]]] = {
        "paper": ("paper", paper),
        "paper, arc-length spacing": ("paper", [resample(c, len(c)) for c in paper]),
        "paper, reversed": ("paper", [c[::-1] for c in paper]),
        "paper, mirrored": ("paper", [c * [-1.0, 1.0] for c in paper]),
        "paper, rotated": (
            "paper",
            [c @ np.array([[np.cos(a), np.sin(a)], [-np.sin(a), np.cos(a)]]) for c, a in zip(paper, angle)],
        ),
    }
    for name, fam in TRAIN_FAMILIES.items():
        if name != "paper":
            drawn = draw_family(fam, count, rng, model_size=None).astype(np.float64)
            sets[name] = ("trained", random_moves(list(drawn), rng))
    for name, fam in HELD_OUT.items():
        drawn = draw_family(fam, count, rng, model_size=None).astype(np.float64)
        sets[name] = ("held out", random_moves(list(drawn), rng))
    if AIRFOIL_WHEEL.exists():
        from curve_vae.training.airfoils import load_airfoils

        sets["airfoils (UIUC)"] = ("real", load_airfoils(AIRFOIL_WHEEL, count, seed=seed))
    return sets


def relative_rmse(inputs: list[np.ndarray], outputs: list[np.ndarray]) -> np.ndarray:
    """RMSE over each input's own points ÷ its bounding-box diagonal (geometry.closeness' first figure, as answers
    state it)."""
    return closeness(inputs, outputs)[0]


def measure(runtime: Any, curves: list[np.ndarray], **options: Any) -> dict[str, float]:
    """One set through `runtime.reconstruct` (options: spacing, pose, …): its row of the suite's table."""
    from curve_vae.inference.reading import Reading

    out = runtime.reconstruct(curves, Reading(**options)).curves
    rel = relative_rmse(curves, out)
    rough_in = np.array([smoothness(c)["roughness"] for c in curves])
    rough_out = np.array([smoothness(o)["roughness"] for o in out])
    return {
        "n_curves": len(curves),
        "rel_rmse_mean": float(rel.mean()),
        "rel_rmse_p95": float(np.percentile(rel, 95)),
        "rel_rmse_max": float(rel.max()),
        "roughness_ratio": float(rough_out.mean() / max(rough_in.mean(), 1e-12)),
        "self_intersecting": float(np.mean([bool(self_intersects(o)) for o in out])),
        # closed-looking inputs (airfoils whose trailing edge closes) touch themselves already
        "self_intersecting_input": float(np.mean([bool(self_intersects(c)) for c in curves])),
    }


def run_suite(runtime: Any, sets: dict[str, tuple[str, list[np.ndarray]]], **options: Any) -> dict[str, Any]:
    """Every set of `suite_sets` measured with the given request options (the sets drawn once by the caller, who
    may measure them again with other options or plot them)."""
    return {name: {"kind": kind, **measure(runtime, curves, **options)} for name, (kind, curves) in sets.items()}


def format_suite(report: dict[str, Any]) -> str:
    """The suite as a text table."""
    head = f"{'set':28s} {'kind':9s} {'rel RMSE':>9s} {'p95':>7s} {'max':>7s} {'rough×':>7s} {'crossing in/out':>16s}"
    lines = [head]
    for name, r in report.items():
        lines.append(
            f"{name:28s} {r['kind']:9s} {100 * r['rel_rmse_mean']:8.2f}% {100 * r['rel_rmse_p95']:6.2f}% "
            f"{100 * r['rel_rmse_max']:6.2f}% {r['roughness_ratio']:7.2f} "
            f"{100 * r.get('self_intersecting_input', 0):7.1f}%/{100 * r['self_intersecting']:5.1f}%"
        )
    return "\n".join(lines)
