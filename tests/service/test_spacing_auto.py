"""Spacing "natural" and "auto": a curve read at even steps of the parameters of the cubic B-spline that fits it
(`geometry.natural_params`), and both readings tried with the reconstruction closest to the input kept."""

from __future__ import annotations

import numpy as np
import pytest

from curve_vae.geometry import natural_params, resample
from curve_vae.service.schemas import ReconstructRequest

from .conftest import bspline_curves


def _drawn_by_arc_length(count: int, seed: int) -> list[np.ndarray]:
    return [resample(3.0 * c + [40.0, -900.0], 161) for c in bspline_curves(count, seed=seed)]


def _rel(curves: list[np.ndarray], out: list[np.ndarray]) -> np.ndarray:
    return np.array(
        [np.sqrt(((a - b) ** 2).sum(-1).mean()) / np.hypot(*np.ptp(a, axis=0)) for a, b in zip(curves, out)]
    )


def test_auto_keeps_the_closer_reading_and_brings_curves_drawn_by_arc_length_closer(shipped_runtime):
    curves = _drawn_by_arc_length(10, seed=31)
    errors = {sp: _rel(curves, shipped_runtime.reconstruct(curves, spacing=sp)[0]) for sp in ("parameter", "natural")}
    auto = _rel(curves, shipped_runtime.reconstruct(curves, spacing="auto")[0])
    picked = np.isclose(auto, errors["parameter"], rtol=1e-9) | np.isclose(auto, errors["natural"], rtol=1e-9)
    assert picked.all(), (auto, errors)  # each curve's answer is one of the two readings'
    assert (auto <= np.maximum(errors["parameter"], errors["natural"]) * (1 + 1e-9)).all()
    assert auto.mean() < 0.9 * errors["parameter"].mean(), (auto.mean(), errors["parameter"].mean())


def test_auto_answers_a_curve_reversed_or_mirrored_alike(shipped_runtime):
    # (a turned curve's bounding box, and so its scale in the model plane, changes with the angle: within a few
    # percent, with every spacing)
    curves = _drawn_by_arc_length(3, seed=32)
    want = _rel(curves, shipped_runtime.reconstruct(curves, spacing="auto")[0])
    for move in (lambda c: c[::-1], lambda c: c * [-1.0, 1.0], lambda c: c[::-1] * [-1.0, 1.0]):
        moved = [move(c) for c in curves]
        np.testing.assert_allclose(_rel(moved, shipped_runtime.reconstruct(moved, spacing="auto")[0]), want, rtol=1e-9)


def test_without_pose_candidates_the_two_readings_still_compete(runtime):
    curves = [c for c in bspline_curves(3, seed=33)] + [resample(c, 90) for c in bspline_curves(2, seed=34)]
    for frame, pose in (("model", "auto"), ("auto", "as_is")):
        out, mse = runtime.reconstruct(curves, frame=frame, pose=pose, spacing="auto")
        one = {
            sp: runtime.reconstruct(curves, frame=frame, pose=pose, spacing=sp)[1] for sp in ("parameter", "natural")
        }
        assert [len(o) for o in out] == [len(c) for c in curves]
        assert np.all(np.isclose(mse, one["parameter"]) | np.isclose(mse, one["natural"]))


def test_the_natural_reading_puts_the_callers_points_at_their_natural_parameters(runtime):
    c = resample(bspline_curves(1, seed=35)[0], 120)
    splines: list = []
    runtime.reconstruct([c], spacing="natural", pose="as_is", splines=splines)
    np.testing.assert_allclose(splines[0].params, natural_params(c), atol=1e-9)  # index placement: at their params


def test_http_takes_both_readings_and_names_a_bad_one(client):
    c = resample(bspline_curves(1, seed=36)[0], 100).tolist()
    for sp in ("natural", "auto"):
        r = client.post("/reconstruct", json={"curves": [c], "spacing": sp, "n_points": 50})
        assert r.status_code == 200, r.text
        assert np.array(r.json()["curves"][0]).shape == (50, 2)
    r = client.post("/reconstruct", json={"curves": [c], "spacing": "natrual"})
    assert r.status_code == 422 and "spacing" in r.text
    with pytest.raises(ValueError):
        ReconstructRequest(curves=[c], spacing="natrual")
