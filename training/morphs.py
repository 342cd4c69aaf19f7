"""The morph suite: sweeps between pairs of curves drawn in one pose, as a designer's variations of a curve are
(the same rotation, in pixels with y down), measured as geometry.morph measures a morph, beside point-wise
blending (paper Fig. 10) and beside /reconstruct's answers on the same curves.

    report = run_morphs(runtime, morph_pairs(paper_test_split(), 40))

Torch-free: it needs only a model directory.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from curve_vae.geometry.morph import end_drift, turn_excess
from curve_vae.training.suite import relative_rmse

#: The measures' thresholds the report counts sweeps beyond: a chord turned this far (degrees) past its ends', an
#: end point this far (share of the ends' diagonal) off the segment between its ends' end points.
TURN_LIMIT = 15.0
DRIFT_LIMIT = 0.15


def morph_pairs(test_curves: np.ndarray, count: int = 40, seed: int = 7) -> list[tuple[np.ndarray, np.ndarray]]:
    """`count` pairs of the paper's curves (consecutive test curves), each pair in one pose of its own: turned by
    one random angle, scaled to pixels and flipped to y down, as a drawing program holds them."""
    rng = np.random.default_rng(seed)
    pairs = []
    for i in range(count):
        a, b = (np.asarray(test_curves[(2 * i + k) % len(test_curves)], np.float64) for k in (0, 1))
        angle = rng.uniform(0, 2 * np.pi)
        turn = np.array([[np.cos(angle), np.sin(angle)], [-np.sin(angle), np.cos(angle)]])
        scale, shift = rng.uniform(2, 6), rng.uniform(100, 400, 2)
        pairs.append(tuple(((c - 64.0) @ turn * scale) * [1.0, -1.0] + shift for c in (a, b)))
    return pairs


def sweep_measures(sweeps: list[np.ndarray]) -> dict[str, float]:
    """Each sweep's turn excess and end drift: their means, maxima and the shares beyond TURN_LIMIT, DRIFT_LIMIT."""
    turns = np.array([turn_excess(s) for s in sweeps])
    drifts = np.array([end_drift(s) for s in sweeps])
    return {
        "turn_excess_mean_deg": float(turns.mean()),
        "turn_excess_max_deg": float(turns.max()),
        "share_turning_beyond_limit": float((turns > TURN_LIMIT).mean()),
        "end_drift_mean": float(drifts.mean()),
        "end_drift_max": float(drifts.max()),
        "share_drifting_beyond_limit": float((drifts > DRIFT_LIMIT).mean()),
    }


def run_morphs(
    runtime: Any, pairs: list[tuple[np.ndarray, np.ndarray]], *, steps: int = 7, readings: dict[str, Any] | None = None
) -> dict[str, Any]:
    """Each reading's sweeps (`steps` even weights) measured, the sweep's ends against /reconstruct's answers with
    the same reading (relative RMSE over the inputs' points, ÷ their diagonal); and point-wise blending."""
    from curve_vae.inference.reading import Reading

    weights = np.array([[1 - t, t] for t in np.linspace(0.0, 1.0, steps)])
    readings = readings or {"default": Reading(), "as_is": Reading(pose="as_is")}
    inputs = [c for pair in pairs for c in pair]
    report: dict[str, Any] = {"pairs": len(pairs), "steps": steps, "turn_limit_deg": TURN_LIMIT}
    report["drift_limit"] = DRIFT_LIMIT
    for name, reading in readings.items():
        sweeps = [np.stack(runtime.interpolate(list(p), weights, reading).curves) for p in pairs]
        ends = [s[k] for s in sweeps for k in (0, -1)]
        alone = runtime.reconstruct(inputs, reading).curves
        end_err, alone_err = relative_rmse(inputs, ends), relative_rmse(inputs, alone)
        report[name] = {
            **sweep_measures(sweeps),
            "ends_rel_rmse_pct": float(100 * end_err.mean()),
            "reconstruct_rel_rmse_pct": float(100 * alone_err.mean()),
            "ends_over_reconstruct": float(end_err.mean() / alone_err.mean()),
        }
    pointwise = [np.stack([(1 - t) * a + t * b for t in np.linspace(0.0, 1.0, steps)]) for a, b in pairs]
    report["pointwise"] = sweep_measures(pointwise)
    return report


def format_morphs(report: dict[str, Any]) -> str:
    """The report as a Markdown table, a row per reading."""
    rows = [
        f"| sweep | turn > {report['turn_limit_deg']:g}° | end drift > {report['drift_limit']:g} | mean turn excess ° "
        "| max turn excess ° | mean end drift | ends' rel. RMSE % | /reconstruct's % | ends ÷ /reconstruct |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for name, r in report.items():
        if not isinstance(r, dict):
            continue
        ends = (
            f"{r['ends_rel_rmse_pct']:.3f} | {r['reconstruct_rel_rmse_pct']:.3f} | {r['ends_over_reconstruct']:.2f}"
            if "ends_rel_rmse_pct" in r
            else "– | – | –"
        )
        rows.append(
            f"| {name} | {100 * r['share_turning_beyond_limit']:.0f}% | {100 * r['share_drifting_beyond_limit']:.0f}% "
            f"| {r['turn_excess_mean_deg']:.1f} | {r['turn_excess_max_deg']:.1f} | {r['end_drift_mean']:.3f} | {ends} |"
        )
    return "\n".join(rows)
