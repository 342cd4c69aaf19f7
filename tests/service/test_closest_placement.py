"""A model placed "closest" (the manifest's spline.placement, `curve-vae export --placement`): the service returns each
input point's closest point on the decoded spline, and picks the pose whose spline passes closest."""

from __future__ import annotations

import numpy as np
import pytest
from fastapi.testclient import TestClient

from curve_vae.geometry import evaluate_bspline, ordered_closest_params, pose_frames, resample
from curve_vae.geometry.adapt import to_model_plane
from curve_vae.inference.reading import Reading
from curve_vae.service.app import create_app
from curve_vae.service.settings import Settings
from tests.helpers import bspline_curves


def _user_curves() -> list[np.ndarray]:
    paper = [0.05 * c + [300.0, -20.0] for c in bspline_curves(6, seed=21)]
    return paper[:3] + [resample(c, 90) for c in paper[3:]]


def test_the_manifest_says_how_points_are_placed(closest_runtime, runtime):
    assert closest_runtime.closest_placement and not runtime.closest_placement


def test_each_returned_point_is_on_the_spline_and_no_further_than_the_models_own_point(closest_runtime, runtime):
    curves = _user_curves()
    for pose in ("as_is", "auto"):
        res = closest_runtime.reconstruct(curves, Reading(pose=pose))
        placed, placed_mse, splines = res.curves, res.mse, res.splines
        for c, s in zip(placed, splines):
            np.testing.assert_allclose(evaluate_bspline(s.control_points, s.params), c, atol=1e-9 * np.abs(c).max())
            assert s.params[0] == 0.0 and s.params[-1] == 1.0 and np.all(np.diff(s.params) >= 0)
        if pose == "as_is":  # the same latents and splines: only where the points sit differs
            res = runtime.reconstruct(curves, Reading(pose=pose))
            own_mse = res.mse
            assert np.all(placed_mse <= own_mse * (1 + 1e-9))
            assert np.all(placed_mse < 0.99 * own_mse), (placed_mse, own_mse)  # closer points, not the same ones


def test_the_pose_kept_is_the_one_whose_spline_passes_closest(closest_runtime):
    c = _user_curves()[4]
    prep = closest_runtime.prepare([c], Reading(pose="search", spacing="parameter"))
    costs = []
    for f in pose_frames(c, chords=3):
        m, _ = to_model_plane(c, f, model_size=closest_runtime.model_size, n_points=closest_runtime.n_points)
        mean, _ = closest_runtime.graphs.encode(m[None].astype(np.float32))
        ctrl = closest_runtime.graphs.decode(mean)[1]
        costs.append((ordered_closest_params(ctrl, [f.to_model(c, closest_runtime.model_size)])[1][0], f))
    best, kept = min(costs, key=lambda cost: cost[0])[1], prep.frames[0]
    # the reader finds every curve's poses at once (geometry.batch.pose_frames_of): the same frames to rounding
    assert (kept.mirror, kept.reverse) == (best.mirror, best.reverse)
    np.testing.assert_allclose([*kept.center, kept.size], [*best.center, best.size], rtol=1e-12, atol=1e-9)
    assert np.cos(kept.rotation - best.rotation) == pytest.approx(1.0, abs=1e-12)


def test_encoding_is_not_changed_by_the_placement(closest_runtime, runtime):
    curves = _user_curves()
    # one reading, one pose, no look again (spacing "auto" chooses among readings, and a look keeps a step, by each
    # placement's own distance)
    one = Reading(pose="as_is", spacing="parameter", looks=0)
    res = closest_runtime.encode(curves, one)
    mean, log_var = res.mean, res.log_var
    res = runtime.encode(curves, one)
    want_mean, want_log_var = res.mean, res.log_var
    np.testing.assert_array_equal(mean, want_mean)
    np.testing.assert_array_equal(log_var, want_log_var)


def test_an_interpolation_row_of_one_curve_is_its_reconstruction(closest_runtime):
    a, b = _user_curves()[:2]
    ra, rb = closest_runtime.reconstruct([a, b], together=True).curves  # a sweep's ends: the pair read as a set
    out = closest_runtime.interpolate([a, b], np.array([[1.0, 0.0], [0.5, 0.5], [0.0, 1.0]])).curves
    np.testing.assert_allclose(out[0], ra, atol=1e-6 * np.abs(ra).max())
    np.testing.assert_allclose(out[-1], rb, atol=1e-6 * np.abs(rb).max())


def test_over_http_the_reconstruction_is_the_runtimes(closest_model_dir, closest_runtime):
    c = _user_curves()[3]
    with TestClient(create_app(Settings(model_dir=closest_model_dir))) as client:
        assert client.get("/model").json()["spline"]["placement"] == "closest"
        r = client.post("/reconstruct", json={"curves": [c.tolist()], "output": "both"})
        assert r.status_code == 200, r.text
        body = r.json()
    rec = closest_runtime.reconstruct([c])
    (want,), mse, splines = rec.curves, rec.mse, rec.splines
    np.testing.assert_allclose(np.array(body["curves"][0]), want, atol=1e-6 * np.abs(want).max())
    np.testing.assert_allclose(body["splines"][0]["params"], splines[0].params, atol=1e-12)
    assert body["mse"][0] == mse[0] or abs(body["mse"][0] - mse[0]) <= 1e-9 * mse[0]


def test_the_shipped_model_is_placed_closest_and_comes_back_closer_so(shipped_runtime):
    assert shipped_runtime.closest_placement  # models/manifest.json: spline.placement
    a = 0.4
    rot = np.array([[np.cos(a), np.sin(a)], [-np.sin(a), np.cos(a)]])
    paper = [0.1 * c @ rot + [50.0, 20.0] for c in bspline_curves(8, seed=31)]
    sets = {"parameter": paper, "arc length": [resample(c, 120) for c in paper]}
    for name, curves in sets.items():
        closest = shipped_runtime.reconstruct(curves).mse
        shipped_runtime.closest_placement = False
        try:
            own = shipped_runtime.reconstruct(curves).mse
        finally:
            shipped_runtime.closest_placement = True
        assert closest.mean() < 0.8 * own.mean(), (name, closest.mean(), own.mean())


def test_the_server_setting_overrides_the_manifest(model_dir, raw_model_dir, closest_runtime):
    from curve_vae.inference.model.manifest import ModelLoadError
    from curve_vae.inference.runtime import CurveRuntime

    c = _user_curves()[4]
    with TestClient(create_app(Settings(model_dir=model_dir, placement="closest"))) as client:  # an "index" manifest
        assert client.get("/model").json()["spline"]["placement"] == "closest"
        body = client.post("/reconstruct", json={"curves": [c.tolist()]}).json()
    (want,) = closest_runtime.reconstruct([c]).curves
    np.testing.assert_allclose(np.array(body["curves"][0]), want, atol=1e-6 * np.abs(want).max())
    assert not CurveRuntime.load(model_dir, providers="cpu", placement="index").closest_placement
    with pytest.raises(ModelLoadError, match="placement closest needs a model with a B-spline head"):
        CurveRuntime.load(raw_model_dir, providers="cpu", placement="closest")
