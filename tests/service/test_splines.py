"""Curves returned as B-splines (`output`): what the model's B-spline head decoded, in the caller's frame."""

from __future__ import annotations

import numpy as np
import pytest
from fastapi.testclient import TestClient

from curve_vae.geometry import arc_length_params, clamped_uniform_knots, evaluate_bspline
from curve_vae.inference.reading import Reading
from curve_vae.service.app import create_app
from curve_vae.service.settings import Settings

C1 = [[0, 0], [1, 2], [2.5, 3.2], [4, 3.5], [5.5, 3], [7, 1.5], [8, 0]]
C2 = [[0, 0], [1.5, 0.5], [3, 2], [4, 4], [5, 6.5], [6.5, 8], [8, 8.5]]
C3 = [[0, 4], [2, 5], [4, 4], [6, 2], [8, 1], [10, 2], [12, 4]]
Z = np.random.default_rng(3).normal(size=(2, 32)).round(6).tolist()

REQUESTS = [
    pytest.param("/decode", {"latents": Z, "n_points": 30, "spacing": "arc_length"}, id="decode"),
    pytest.param("/decode", {"latents": Z, "frames": [{"center": [5, -3], "size": 0.01}] * 2}, id="decode-framed"),
    pytest.param("/reconstruct", {"curves": [C1, C2]}, id="reconstruct"),
    pytest.param("/reconstruct", {"curves": [C1, C2], "n_points": 64}, id="reconstruct-64"),
    pytest.param("/interpolate", {"curves": [C1, C2, C3], "steps": 3}, id="interpolate-triplet"),
    pytest.param("/sample", {"count": 3, "seed": 5, "frame": {"center": [0, 0], "size": 2}}, id="sample"),
    pytest.param("/augment", {"curves": [C1, C2, C3], "count": 4, "seed": 2, "mode": "triplet"}, id="augment"),
]


@pytest.fixture(params=["even", "learned"])
def head_client(request, make_client, params_model_dir, params_runtime):
    """A client of a model whose head places its points evenly in the parameter, or at parameters of its own."""
    if request.param == "even":
        return make_client()
    client = TestClient(create_app(Settings(model_dir=params_model_dir), runtime=params_runtime))
    request.addfinalizer(lambda: client.__exit__(None, None, None))
    return client.__enter__()


@pytest.mark.parametrize(("path", "body"), REQUESTS)
def test_returned_splines_evaluate_back_to_the_returned_points(head_client, path, body):
    client = head_client
    points = client.post(path, json=body).json()["curves"]
    both = client.post(path, json={**body, "output": "both"}).json()
    only = client.post(path, json={**body, "output": "bspline"}).json()
    assert "curves" not in only and "splines" not in client.post(path, json=body).json()
    np.testing.assert_allclose(both["curves"], points, rtol=0, atol=1e-12)  # asking for splines changes no point
    assert only["splines"] == both["splines"] and len(both["splines"]) == len(points)
    for curve, spline in zip(points, both["splines"], strict=True):
        assert spline["degree"] == 3 and np.shape(spline["control_points"]) == (31, 2)
        np.testing.assert_array_equal(spline["knots"], clamped_uniform_knots(31))
        assert len(spline["params"]) == len(curve) and np.all(np.diff(spline["params"]) >= 0)
        assert spline["params"][0] == pytest.approx(0, abs=1e-12) and spline["params"][-1] == pytest.approx(1)
        scale = np.ptp(np.array(curve), axis=0).max()
        again = evaluate_bspline(spline["control_points"], spline["params"])
        np.testing.assert_allclose(again, curve, rtol=0, atol=1e-12 * scale)


def test_model_info_names_the_spline_head(client):
    spline = client.get("/model").json()["spline"]
    assert spline["n_ctrl"] == 31 and spline["degree"] == 3 and len(spline["knots"]) == 35
    assert spline["learned_params"] is False and spline["placement"] == "index"


def test_model_info_tells_a_head_with_learned_parameters(params_model_dir, params_runtime):
    with TestClient(create_app(Settings(model_dir=params_model_dir), runtime=params_runtime)) as client:
        assert client.get("/model").json()["spline"]["learned_params"] is True


def test_a_model_without_a_head_refuses_splines_and_says_why(raw_model_dir, raw_runtime):
    with TestClient(create_app(Settings(model_dir=raw_model_dir), runtime=raw_runtime)) as client:
        assert client.get("/model").json()["spline"] is None
        r = client.post("/reconstruct", json={"curves": [C1], "output": "bspline"})
        assert r.status_code == 422
        assert r.json()["detail"].startswith('output: "bspline" needs a model with a B-spline head')
        assert client.post("/reconstruct", json={"curves": [C1]}).status_code == 200


def test_npy_augment_is_points_only(client):
    body = {"curves": [C1, C2], "count": 3, "format": "npy", "output": "both"}
    r = client.post("/augment", json=body)
    assert r.status_code == 422 and r.json()["detail"].startswith('output: only "points" with format npy')


def test_unknown_output_is_a_422(client):
    r = client.post("/decode", json={"latents": Z, "output": "nurbs"})
    assert r.status_code == 422 and "output" in r.json()["detail"]


def test_a_learned_head_places_the_points_at_its_own_parameters(params_runtime):
    """The decoder's `params` output is where its points sit: the model's own 161 points come back at exactly those
    parameters, other counts between them, arc-length spacing evenly in length, and the input's positions along
    them; the returned spline at the returned parameters is the returned curve."""
    rt = params_runtime
    z = np.random.default_rng(4).normal(size=(1, 32))
    _, ctrl, params = rt.graphs.decode(z)
    assert params.shape == (1, 161) and params[0, 0] == 0 and params[0, -1] == pytest.approx(1)
    assert np.all(np.diff(params[0]) > 0) and np.ptp(np.diff(params[0])) > 1e-4  # uneven: not i/160
    for ask in ({}, {"n_points": 161}):
        splines = rt.decode(z, **ask).splines
        np.testing.assert_allclose(splines[0].params, params[0], atol=1e-7)
    splines = rt.decode(z, n_points=81).splines
    np.testing.assert_allclose(splines[0].params, params[0, ::2], atol=1e-7)  # "parameter": the model's spacing
    splines = rt.decode(z, n_points=60, spacing="arc_length").splines  # evenly in length, whatever the head's params
    np.testing.assert_allclose(splines[0].params, arc_length_params(ctrl[0].astype(np.float64), 60), atol=1e-12)
    t = np.linspace(0, 1, 41) ** 1.3
    drawn = np.stack([10 * t, np.sin(3 * t)], axis=1)
    rec = rt.reconstruct([drawn], Reading(pose="as_is"))
    out, s = rec.curves, rec.splines[0]
    assert len(s.params) == 41 and np.all(np.diff(s.params) > 0)
    np.testing.assert_allclose(evaluate_bspline(s.control_points, s.params), out[0], atol=1e-9)
