"""A prior's samples against held-out curves, with the field's metrics (evaluation.generation) and their intervals
over seeds: what `curve-vae evaluate-prior` prints and docs/RESULTS.md tabulates.

Samples come from `CurveRuntime.sample(prior=…)` exactly as /sample makes them (in the frame of their nearest
reference curve, redrawn until valid), and every set — samples, held-out curves, the prior's own training curves —
is resampled to `points` points evenly by arc length, so that shapes compare point by point as BézierGAN's 192-point
airfoils do. Each seed draws `count` samples.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from curve_vae.evaluation import generation as g
from curve_vae.geometry import resample

#: BézierGAN's airfoils have 192 points; MMD compares 2000 samples against the test set.
POINTS = 192
SAMPLES = 2000


def resampled(curves: Sequence[np.ndarray], points: int = POINTS) -> np.ndarray:
    """(N, points, 2): each curve evenly by arc length (closed ones too: their first point kept first)."""
    return np.stack([resample(np.asarray(c, np.float64), points) for c in curves])


def evaluate_prior(
    runtime: Any,
    prior: str,
    held_out: Sequence[np.ndarray],
    train: Sequence[np.ndarray],
    *,
    seeds: Sequence[int] = (0, 1, 2, 3, 4),
    count: int = SAMPLES,
    points: int = POINTS,
    likelihood_samples: int = 500,
    lsc_lines: int = 100,
) -> dict[str, Any]:
    """Every metric of evaluation.generation per seed, and its mean ± 1.96·σ/√n over the seeds."""
    ref, tr = resampled(held_out, points), resampled(train, points)
    named = runtime.priors.get(prior)
    runs: dict[str, list[float]] = {}

    def add(name: str, value: float) -> None:
        runs.setdefault(name, []).append(float(value))

    for seed in seeds:
        made = runtime.sample(count, seed=seed, prior=prior)
        gen = resampled(list(made.curves), points)
        add("valid", 1 - made.invalid / count)
        add("rejected_share", made.rejected / (made.rejected + count))
        for k, v in shape_metrics(gen, ref).items():
            add(k, v)
        add("diversity_ratio", g.diversity_ratio(gen, tr))
        add("novelty", g.novelty(gen, tr))
        add("copy_rate", g.copy_rate(gen, tr))
        near = g.nearest_distance(gen, ref)
        add("nn_to_held_out", float(np.median(near)))
        if likelihood_samples:
            add("mean_log_likelihood", g.mean_log_likelihood(gen[:likelihood_samples], ref))
        if lsc_lines and named is not None:
            add(
                "lsc",
                g.lsc(
                    _shape_decoder(runtime, points), _latent_box(named), np.random.default_rng(seed), lines=lsc_lines
                ),
            )
    base = float(np.median(g.nearest_distance(ref, tr)))  # the held-out curves' own distance to the training ones
    return {
        "real": real_yardstick(ref, tr, count),
        "prior": prior,
        "seeds": list(seeds),
        "samples_per_seed": count,
        "points": points,
        "held_out": len(ref),
        "train": len(tr),
        "held_out_nn_to_train": base,
        "metrics": {k: {"mean": g.interval(v)[0], "pm": g.interval(v)[1], "runs": v} for k, v in runs.items()},
    }


def shape_metrics(gen: np.ndarray, ref: np.ndarray) -> dict[str, float]:
    """The metrics of a set of shapes against the reference set alone: MMD both ways, precision/recall/density/
    coverage, coverage at EngiOpt's radius, RVOD, and Vendi and DPP diversity (on the first 1,000 and 500)."""
    return {
        "mmd_ideallab": g.mmd_ideallab(gen, ref),
        "mmd_gaussian": g.mmd_gaussian(gen, ref),
        **g.prdc(gen, ref),
        "coverage_radius": g.coverage(gen, ref),
        "rvod": g.rvod(gen, ref),
        "vendi": g.vendi(gen[:1000]),
        "dpp": g.dpp_diversity(gen[:500]),
    }


def real_yardstick(ref: np.ndarray, train: np.ndarray, count: int = SAMPLES) -> dict[str, float]:
    """`shape_metrics` with the training curves (at most `count`, the first) in the samples' place: what a generator
    that returned the data itself would score against the held-out curves."""
    return shape_metrics(train[:count], ref)


def _latent_box(prior: Any) -> tuple[np.ndarray, np.ndarray]:
    """The latent box LSC draws its lines in: the 1st to 99th percentiles of the reference latents, per dimension
    (BézierGAN's latents are uniform on [0, 1]: its box is the latent space itself)."""
    z = prior.reference.latents
    return np.percentile(z, 1, axis=0), np.percentile(z, 99, axis=0)


def _shape_decoder(runtime: Any, points: int) -> Any:
    def decode(z: np.ndarray) -> np.ndarray:
        return resampled(list(runtime.decode(z).curves), points)

    return decode


def format_report(report: dict[str, Any]) -> str:
    """The report as a text table: each metric's mean ± its interval over the seeds."""
    lines = [
        f"prior {report['prior']}: {report['samples_per_seed']} samples × {len(report['seeds'])} seeds against "
        f"{report['held_out']} held-out curves ({report['train']} training curves), {report['points']} points by arc "
        f"length; held-out curves' median distance to the training ones: {report['held_out_nn_to_train']:.4g}"
    ]
    real = report.get("real", {})
    lines.append(f"  {'metric':22s} {'samples':>12s}   {'interval':9s} {'real':>10s}")
    for name, m in report["metrics"].items():
        yard = f"{real[name]:10.5g}" if name in real else ""
        lines.append(f"  {name:22s} {m['mean']:12.5g} ± {m['pm']:<9.3g} {yard}")
    lines.append("  (real: the training curves in the samples' place)")
    return "\n".join(lines)
