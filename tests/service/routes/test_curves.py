"""POST /encode, /decode, /reconstruct and /interpolate (service.routes.curves) through TestClient: shapes, frames and
lengths, the runtime's own answers over JSON, and curves returned as B-splines (`output`) in the caller's frame."""

from __future__ import annotations

import numpy as np
import pytest
from fastapi.testclient import TestClient

from curve_vae.geometry import arc_length_params, clamped_uniform_knots, evaluate_bspline, fit_frame, mse_per_curve
from curve_vae.inference.reading import Reading
from curve_vae.service.app import create_app
from curve_vae.service.settings import Settings

CURVE = [[0, 0], [1, 2], [2.5, 3.2], [4, 3.5], [5.5, 3], [7, 1.5], [8, 0]]


def test_encode(client, curves, runtime):
    c = curves(2, 100) * 0.5 + 300
    r = client.post("/encode", json={"curves": c.tolist(), "pose": "as_is"})
    assert r.status_code == 200
    body = r.json()
    assert np.shape(body["mean"]) == np.shape(body["log_var"]) == (2, 32)
    assert body["frames"] == [
        {
            "center": list(fit_frame(x).center),
            "size": fit_frame(x).size,
            "rotation": 0.0,
            "mirror": False,
            "reverse": False,
        }
        for x in c
    ]
    mean = runtime.encode(list(c), Reading(pose="as_is")).mean
    np.testing.assert_allclose(body["mean"], mean, rtol=1e-6)


def test_encode_model_frame_has_no_frames(client):
    r = client.post(
        "/encode", json={"curves": [[[14, 64], [40, 100], [64, 110], [90, 95], [114, 64]]], "frame": "model"}
    )
    assert r.status_code == 200 and r.json()["frames"] is None


def test_decode_in_the_model_plane_and_in_a_frame(client, runtime):
    z = np.random.default_rng(0).normal(size=(3, 32))
    r = client.post("/decode", json={"latents": z.tolist()})
    assert r.status_code == 200
    plane = np.array(r.json()["curves"])
    assert plane.shape == (3, 161, 2)
    np.testing.assert_allclose(plane, runtime.graphs.decode_model(z), rtol=1e-6)
    frames = [{"center": [1.0, -2.0], "size": 0.5}] * 3
    r = client.post("/decode", json={"latents": z.tolist(), "frames": frames, "n_points": 40})
    framed = np.array(r.json()["curves"])
    assert framed.shape == (3, 40, 2)
    ext = framed.max(axis=1) - framed.min(axis=1)
    assert np.all(ext.max(axis=1) < 2.0)  # an untrained decoder's scribble, scaled to the frame


def test_encode_then_decode_in_the_returned_frames_is_the_reconstruction_but_for_its_ends(client, runtime, curves):
    """/decode draws the latent /encode returns as the model does; /reconstruct's answer is that drawing with its ends
    moved onto the input's (inference.placing)."""
    c = (curves(2) * 3 - 11).tolist()  # read as given (spacing "parameter"): the returned points are the model's
    enc = client.post("/encode", json={"curves": c, "spacing": "parameter"}).json()
    dec = client.post("/decode", json={"latents": enc["mean"], "frames": enc["frames"]}).json()
    rec = client.post("/reconstruct", json={"curves": c, "spacing": "parameter"}).json()
    np.testing.assert_allclose([r[0] for r in rec["curves"]], [x[0] for x in c], atol=1e-9)
    np.testing.assert_allclose([r[-1] for r in rec["curves"]], [x[-1] for x in c], atol=1e-9)
    runtime.reader.keep_ends = False
    try:
        drawn = client.post("/reconstruct", json={"curves": c, "spacing": "parameter"}).json()
    finally:
        runtime.reader.keep_ends = True
    np.testing.assert_allclose(dec["curves"], drawn["curves"], rtol=1e-6, atol=1e-6)


def test_reconstruct(client, curves):
    inputs = [curves(1, 50)[0].tolist(), (curves(1, 161, seed=1)[0] * 10).tolist(), CURVE]
    r = client.post("/reconstruct", json={"curves": inputs})
    assert r.status_code == 200
    body = r.json()
    assert [len(c) for c in body["curves"]] == [50, 161, 7]
    expected = [mse_per_curve(np.array([a]), np.array([b]))[0] for a, b in zip(inputs, body["curves"], strict=True)]
    np.testing.assert_allclose(body["mse"], expected, rtol=1e-9)


def test_reconstruct_follows_scale_and_shift_over_http(client, curves):
    c = curves(1, 80, seed=3)[0]
    base = np.array(client.post("/reconstruct", json={"curves": [c.tolist()]}).json()["curves"][0])
    moved = np.array(
        client.post("/reconstruct", json={"curves": [(c * 40 + [1e4, -3e3]).tolist()]}).json()["curves"][0]
    )
    np.testing.assert_allclose(moved, base * 40 + [1e4, -3e3], rtol=0, atol=1e-6 * 128 * 40 + 1e-11)


def test_reconstruct_n_points(client):
    r = client.post("/reconstruct", json={"curves": [CURVE, CURVE], "n_points": 25})
    assert np.shape(r.json()["curves"]) == (2, 25, 2)


@pytest.mark.parametrize(
    "body,rows",
    [
        pytest.param({"steps": 5}, [[1, 0], [0.75, 0.25], [0.5, 0.5], [0.25, 0.75], [0, 1]], id="pair-steps"),
        pytest.param({}, [[1, 0], [0.75, 0.25], [0.5, 0.5], [0.25, 0.75], [0, 1]], id="pair-default-5"),
        pytest.param({"weights": [[0.3, 0.7], [-0.5, 1.5]]}, [[0.3, 0.7], [-0.5, 1.5]], id="pair-weights"),
    ],
)
def test_interpolate_pair(client, curves, body, rows):
    c = curves(2, 120).tolist()
    r = client.post("/interpolate", json={"curves": c, **body})
    assert r.status_code == 200
    out = r.json()
    np.testing.assert_allclose(out["weights"], rows)
    assert np.shape(out["curves"]) == (len(rows), 120, 2)
    assert len(out["frames"]) == len(rows)


def test_interpolate_triplet_grid_and_weights(client, curves):
    c = curves(3, 161).tolist()
    grid = client.post("/interpolate", json={"curves": c, "steps": 3}).json()
    assert len(grid["weights"]) == 6 and grid["weights"][0] == [1, 0, 0] and grid["weights"][-1] == [0, 0, 1]
    np.testing.assert_allclose(np.sum(grid["weights"], axis=1), 1.0)
    one = client.post("/interpolate", json={"curves": c, "weights": [[0.2, 0.3, 0.5]], "n_points": 64}).json()
    assert np.shape(one["curves"]) == (1, 64, 2)


def test_interpolate_n_way_model_frame(client, curves):
    c = curves(5, 161).tolist()
    r = client.post("/interpolate", json={"curves": c, "weights": [[0.2] * 5], "frame": "model"})
    assert r.status_code == 200 and r.json()["frames"] is None


def test_a_curve_interpolated_with_itself_is_its_reconstruction(client, curves):
    c = (curves(1, 161)[0] * 0.1 + 500).tolist()
    inter = client.post("/interpolate", json={"curves": [c, c], "steps": 3}).json()
    rec = client.post("/reconstruct", json={"curves": [c]}).json()
    for curve in inter["curves"]:
        np.testing.assert_allclose(curve, rec["curves"][0], rtol=0, atol=1e-9 * 500)


def test_a_pair_is_read_in_one_pose(client, curves):
    c = [(curves(1, 161)[0] * 0.1).tolist(), (curves(1, 161, seed=9)[0] + 500).tolist()]
    frames = client.post("/interpolate", json={"curves": c, "steps": 3}).json()["frames"]
    assert len({(f["rotation"], f["mirror"], f["reverse"]) for f in frames}) == 1  # one pose; centres, sizes blend


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
