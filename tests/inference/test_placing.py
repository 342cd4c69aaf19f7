"""inference.placing: a reconstruction mapped back to its caller, every curve of a batch at once as each alone."""

from __future__ import annotations

import numpy as np
import pytest

from curve_vae.geometry import evaluate_bspline, mse_per_curve
from curve_vae.inference.placing import placed_to_caller, to_caller
from curve_vae.inference.reading import Reading
from tests.helpers import bspline_curves

ONE_PASS = Reading(pose="canonical", spacing="parameter")


def _callers(count: int, seed: int = 0) -> list[np.ndarray]:
    """Open and closed curves of many lengths in any pose and frame, as callers post them."""
    rng = np.random.default_rng(seed)
    out = []
    for i, c in enumerate(bspline_curves(count, 161, seed=seed)):
        c = c[: rng.integers(4, 162)] @ np.linalg.qr(rng.normal(size=(2, 2)))[0] * rng.uniform(0.1, 10) + rng.normal(
            0, 100, 2
        )
        out.append(np.concatenate([c, c[:1]]) if i % 3 == 0 else c[::-1] if i % 4 == 0 else c)
    return out


@pytest.mark.parametrize("reading", [ONE_PASS, Reading(pose="as_is", spacing="parameter")], ids=["canonical", "as_is"])
def test_a_batch_maps_back_as_each_curve_does_alone(shipped_runtime, reading):
    rt = shipped_runtime
    prep = rt.prepare(_callers(20), reading)
    curves, splines, mse = placed_to_caller(rt.graphs, prep)
    for pts, row, curve, spline, err in zip(prep.inputs, prep.rows, curves, splines, mse):
        closed = np.array_equal(pts[0], pts[-1])
        ctrl = row.ctrl.astype(np.float64)
        if closed:
            ctrl[0] = ctrl[-1] = (ctrl[0] + ctrl[-1]) / 2
        own, s = to_caller(rt.graphs, row.decoded, row.frame, n_points=None, fractions=row.feet, ctrl=ctrl)
        scale = np.abs(pts).max()
        np.testing.assert_allclose(curve, own, rtol=0, atol=1e-12 * scale)
        np.testing.assert_allclose(spline.control_points, s.control_points, rtol=0, atol=1e-12 * scale)
        np.testing.assert_allclose(spline.params, s.params, rtol=0, atol=1e-12)
        np.testing.assert_allclose(err, mse_per_curve(pts[None], own[None])[0], rtol=1e-9)
        np.testing.assert_allclose(evaluate_bspline(spline.control_points, spline.params), curve, atol=1e-9 * scale)
        if closed:
            np.testing.assert_array_equal(curve[0], curve[-1])


def test_batches_of_1_7_and_128_give_the_same_answers(shipped_runtime):
    rt = shipped_runtime
    curves = _callers(128, seed=1)
    whole = rt.reconstruct(curves, ONE_PASS)
    for size in (1, 7):
        for start in range(0, 28, size):
            part = rt.reconstruct(curves[start : start + size], ONE_PASS)
            for a, b in zip(part.curves, whole.curves[start : start + size]):
                np.testing.assert_allclose(a, b, rtol=1e-9, atol=1e-9 * np.abs(b).max())
            np.testing.assert_allclose(part.mse, whole.mse[start : start + size], rtol=1e-9)
            np.testing.assert_array_equal(part.latents, whole.latents[start : start + size])


def test_a_batch_of_curves_without_frames_is_left_to_the_curve_by_curve_path(shipped_runtime):
    rt = shipped_runtime
    prep = rt.prepare([c * 0.5 + 30 for c in bspline_curves(3)], Reading(frame="model", spacing="parameter"))
    assert placed_to_caller(rt.graphs, prep) is None
    assert len(rt.reconstruct(prep.inputs, Reading(frame="model")).curves) == 3
