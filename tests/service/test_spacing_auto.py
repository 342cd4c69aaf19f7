"""Spacing "natural" and "auto": a curve read at even steps of the parameters of the cubic B-spline that fits it
(`geometry.natural_params`), and the readings tried with the reconstruction closest to the input kept."""

from __future__ import annotations

import numpy as np
import pytest

from curve_vae.geometry import natural_params, natural_readings, resample
from curve_vae.inference import reader as reader_module
from curve_vae.inference.reading import Reading
from curve_vae.inference.results import Reconstruction
from curve_vae.service.schemas import ReconstructRequest
from tests.helpers import bspline_curves


def _drawn_by_arc_length(count: int, seed: int) -> list[np.ndarray]:
    return [resample(3.0 * c + [40.0, -900.0], 161) for c in bspline_curves(count, seed=seed)]


def _rel(curves: list[np.ndarray], out: list[np.ndarray]) -> np.ndarray:
    return np.array(
        [np.sqrt(((a - b) ** 2).sum(-1).mean()) / np.hypot(*np.ptp(a, axis=0)) for a, b in zip(curves, out)]
    )


def _each_reading(runtime, curves, monkeypatch, **options) -> dict[str, Reconstruction]:
    """What /reconstruct gives each reading spacing "auto" tries alone: the points as given, the closest natural
    fit's reading, and the reading of the fit from the arc-length fractions (where it ends elsewhere)."""
    out = {sp: runtime.reconstruct(curves, Reading(spacing=sp, **options)) for sp in ("parameter", "natural")}
    with monkeypatch.context() as m:
        m.setattr(reader_module, "natural_readings_of", lambda many: [natural_readings(pts)[-1:] for pts in many])
        out["natural, from arc length"] = runtime.reconstruct(curves, Reading(spacing="natural", **options))
    return out


def test_auto_keeps_the_closest_reading_and_brings_curves_drawn_by_arc_length_closer(shipped_runtime, monkeypatch):
    curves = _drawn_by_arc_length(10, seed=31)
    # pose "search" (the learned reading encodes only two of these candidates: tests/inference/test_ranker.py)
    each = _each_reading(shipped_runtime, curves, monkeypatch, pose="search")
    errors = {sp: _rel(curves, out.curves) for sp, out in each.items()}
    auto = _rel(curves, shipped_runtime.reconstruct(curves, Reading(pose="search", spacing="search")).curves)
    picked = np.any([np.isclose(auto, e, rtol=1e-9) for e in errors.values()], axis=0)
    assert picked.all(), (auto, errors)  # each curve's answer is one of the readings'
    assert (auto <= np.max(list(errors.values()), axis=0) * (1 + 1e-9)).all()
    assert auto.mean() < 0.8 * errors["parameter"].mean(), (auto.mean(), errors["parameter"].mean())


def test_auto_answers_a_curve_reversed_or_mirrored_alike(shipped_runtime):
    # (a turned curve's bounding box, and so its scale in the model plane, changes with the angle: within a few
    # percent, with every spacing)
    curves = _drawn_by_arc_length(3, seed=32)
    want = _rel(curves, shipped_runtime.reconstruct(curves, Reading(spacing="search")).curves)
    for move in (lambda c: c[::-1], lambda c: c * [-1.0, 1.0], lambda c: c[::-1] * [-1.0, 1.0]):
        moved = [move(c) for c in curves]
        np.testing.assert_allclose(
            _rel(moved, shipped_runtime.reconstruct(moved, Reading(spacing="search")).curves), want, rtol=1e-9
        )


def test_without_pose_candidates_the_readings_still_compete(runtime, monkeypatch):
    curves = [c for c in bspline_curves(3, seed=33)] + [resample(c, 90) for c in bspline_curves(2, seed=34)]
    for frame, pose in (("model", "search"), ("auto", "as_is")):
        res = runtime.reconstruct(curves, Reading(frame=frame, pose=pose, spacing="search"))
        out, mse = res.curves, res.mse
        one = _each_reading(runtime, curves, monkeypatch, frame=frame, pose=pose)
        assert [len(o) for o in out] == [len(c) for c in curves]
        assert np.any([np.isclose(mse, rec.mse) for rec in one.values()], axis=0).all()


def test_the_natural_reading_puts_the_callers_points_at_their_natural_parameters(runtime):
    c = resample(bspline_curves(1, seed=35)[0], 120)
    splines = runtime.reconstruct([c], Reading(spacing="natural", pose="as_is")).splines
    np.testing.assert_allclose(splines[0].params, natural_params(c), atol=1e-9)  # index placement: at their params


def test_http_takes_both_readings_and_names_a_bad_one(client):
    c = resample(bspline_curves(1, seed=36)[0], 100).tolist()
    for sp in ("natural", "search"):
        r = client.post("/reconstruct", json={"curves": [c], "spacing": sp, "n_points": 50})
        assert r.status_code == 200, r.text
        assert np.array(r.json()["curves"][0]).shape == (50, 2)
    r = client.post("/reconstruct", json={"curves": [c], "spacing": "natrual"})
    assert r.status_code == 422 and "spacing" in r.text
    with pytest.raises(ValueError):
        ReconstructRequest(curves=[c], spacing="natrual")


def test_a_natural_reading_that_puts_the_points_where_they_are_is_not_tried_again(runtime, monkeypatch):
    """A curve at the paper's own spacing: its closest natural fit gives its points their index fractions
    (reader.SAME_READING), so "search" does not try that reading beside "parameter"; a curve drawn by arc length gets
    every natural reading in every pose."""
    even = bspline_curves(1, seed=37)[0]
    drawn = resample(even, len(even))
    assert np.abs(natural_params(even) - np.linspace(0, 1, len(even))).max() <= reader_module.SAME_READING
    rows: list[int] = []
    encode = runtime.graphs.encode
    monkeypatch.setattr(runtime.graphs, "encode", lambda x: rows.append(len(x)) or encode(x))
    runtime.reconstruct([even], Reading(spacing="search"))
    runtime.reconstruct([drawn], Reading(spacing="search"))
    poses = 2 * reader_module.POSE_CHORD_COUNT
    assert rows[0] == poses * len(natural_readings(even))  # "parameter", and the readings but the closest
    assert rows[1] == poses * (1 + len(natural_readings(drawn)))
