"""POST /fit and POST /revolve (issue 5): B-spline fits and surfaces of revolution, geometry behind REST."""

from __future__ import annotations

import numpy as np
import pytest
from fastapi.testclient import TestClient

from curve_vae.geometry import clamped_uniform_knots, fit_bspline, random_control_points, sample_bspline
from curve_vae.geometry.bspline import AUTO_CTRL
from curve_vae.service.app import create_app
from curve_vae.service.settings import Settings

CURVE = [[0, 0], [1, 2], [2.5, 3.2], [4, 3.5], [5.5, 3], [7, 1.5], [8, 0]]
VASE = [[0, 0], [3, 0], [4, 1], [3, 3], [2.5, 5], [3, 7], [0, 7]]  # both ends on the axis x = 0
CLUSTER_AND_ONE_FAR = [[i / 100, i % 2 / 100] for i in range(10)] + [[5, 5]]  # middle knot spans hold no point

# ----------------------------------------------------------------------------- fit


@pytest.mark.parametrize("n_ctrl", [10, 6])
def test_fit_recovers_a_known_bspline_from_its_exact_samples(client, n_ctrl):
    ctrl = random_control_points(np.random.default_rng(n_ctrl), 3, n_ctrl=n_ctrl) * 13 - 400  # any frame
    r = client.post("/fit", json={"curves": sample_bspline(ctrl, 161).tolist(), "n_ctrl": n_ctrl, "param": "uniform"})
    assert r.status_code == 200, r.text
    fits = r.json()["fits"]
    assert len(fits) == 3
    for f, c in zip(fits, ctrl, strict=True):
        np.testing.assert_allclose(f["control_points"], c, rtol=0, atol=1e-6)
        np.testing.assert_allclose(f["knots"], clamped_uniform_knots(n_ctrl))
        assert f["degree"] == 3 and f["rms_error"] < 1e-9 and f["max_error"] < 1e-9


def test_fit_without_n_ctrl_picks_the_fewest_control_points_within_tolerance(client):
    ctrl = random_control_points(np.random.default_rng(1), 1)[0]
    c = sample_bspline(ctrl, 200)
    diag = np.linalg.norm(np.ptp(c, axis=0))
    for tolerance in (1e-2, 1e-3):
        body = {"curves": [c.tolist()], "n_points": 50, "tolerance": tolerance}
        f = client.post("/fit", json=body).json()["fits"][0]
        n = f["n_ctrl"]
        assert np.shape(f["control_points"]) == (n, 2) and len(f["knots"]) == n + 4
        assert f["rms_error"] <= tolerance * diag
        fewer = [k for k in AUTO_CTRL if k < n]
        if fewer:  # the next smaller count tried does not reach the tolerance
            assert fit_bspline(c, fewer[-1], param="chord").rms_error > tolerance * diag
        assert np.shape(f["curve"]) == (50, 2)
        np.testing.assert_allclose(f["curve"][0], f["control_points"][0], atol=1e-9)  # clamped: ends at its ends
        np.testing.assert_allclose(f["curve"][-1], f["control_points"][-1], atol=1e-9)


def test_fit_of_a_short_curve_without_n_ctrl(client):
    """The README's 7-point example: no n_ctrl, no error; at most as many control points as points."""
    f = client.post("/fit", json={"curves": [CURVE]}).json()["fits"][0]
    assert 4 <= f["n_ctrl"] <= len(CURVE)


def test_fit_works_before_any_model_is_loaded(model_dir):
    client = TestClient(create_app(Settings(model_dir=model_dir)))  # no lifespan: no model
    assert client.post("/encode", json={"curves": [CURVE]}).status_code == 503
    r = client.post("/fit", json={"curves": [CURVE], "n_ctrl": 4})
    assert r.status_code == 200 and np.shape(r.json()["fits"][0]["control_points"]) == (4, 2)


@pytest.mark.parametrize(
    "body,detail",
    [
        pytest.param(
            {"curves": [CURVE, CURVE[:5]], "n_ctrl": 6},
            "curves[1]: n_ctrl=6 control points need at least as many points, got 5",
            id="more-control-points-than-points",
        ),
        pytest.param({"curves": [CURVE], "n_ctrl": 3}, "n_ctrl: Input should be greater than or equal to 4", id="n3"),
        pytest.param({"curves": [CURVE], "param": "arc"}, "param: Input should be 'chord' or 'uniform'", id="param"),
        pytest.param(
            {"curves": [CLUSTER_AND_ONE_FAR], "n_ctrl": 8},
            "curves[0]: no unique least-squares spline with 8 control points",
            id="knot-spans-without-points",
        ),
        pytest.param(
            {"curves": [[[0, 0]] * 8 + [[1, 1], [2, 2], [3, 3]]], "n_ctrl": 10},
            "curves[0]: no unique least-squares spline with 10 control points",
            id="points-bunched-together",
        ),
        pytest.param(
            {"curves": [CURVE], "n_points": 1}, "n_points: Input should be greater than or equal to 2", id="np"
        ),
    ],
)
def test_fit_rejects_what_it_cannot_fit(client, body, detail):
    r = client.post("/fit", json=body)
    assert r.status_code == 422, r.text
    assert r.json()["detail"].startswith(detail), r.json()["detail"]


# ----------------------------------------------------------------------------- revolve


def _parse_obj(text: str) -> tuple[np.ndarray, np.ndarray]:
    lines = text.splitlines()
    v = np.array([[float(x) for x in line.split()[1:]] for line in lines if line.startswith("v ")])
    f = np.array([[int(x) - 1 for x in line.split()[1:]] for line in lines if line.startswith("f ")])
    return v, f


def _edge_uses(faces: np.ndarray) -> np.ndarray:
    edges = np.sort(faces[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2), axis=1)
    return np.unique(edges, axis=0, return_counts=True)[1]


def test_a_profile_touching_the_axis_gives_a_closed_watertight_vase(client):
    segments = 32
    r = client.post("/revolve", json={"curve": VASE, "segments": segments})
    assert r.status_code == 200, r.text
    assert r.headers["content-type"].startswith("model/obj")
    assert r.headers["content-disposition"] == 'attachment; filename="surface.obj"'
    v, f = _parse_obj(r.text)
    rings = len(VASE) - 2  # the two end points are poles on the axis
    assert len(v) == 2 + rings * segments == int(r.headers["x-mesh-vertices"])
    assert len(f) == 2 * segments + 2 * (rings - 1) * segments == int(r.headers["x-mesh-faces"])
    uses = _edge_uses(f)
    assert (uses == 2).all() and r.headers["x-mesh-closed"] == "true"  # every edge joins exactly two triangles
    assert len(v) - len(uses) + len(f) == 2  # Euler characteristic of a sphere
    # outward-facing: the enclosed volume is positive
    tri = v[f]
    volume = np.einsum("ij,ij->i", tri[:, 0], np.cross(tri[:, 1], tri[:, 2])).sum() / 6
    assert volume > 0
    radius = np.hypot(v[:, 0], v[:, 2])  # about the y axis through x = 0
    assert radius.max() == pytest.approx(4.0, rel=1e-5) and v[:, 1].min() == 0 and v[:, 1].max() == 7


def test_an_open_profile_gives_an_open_band(client):
    r = client.post("/revolve", json={"curve": CURVE, "segments": 12, "axis": "x", "axis_position": -1})
    assert r.status_code == 200
    v, f = _parse_obj(r.text)
    assert len(v) == 7 * 12 and len(f) == 2 * 6 * 12 and r.headers["x-mesh-closed"] == "false"
    assert (_edge_uses(f) <= 2).all()
    # about the horizontal line y = -1: x runs along the axis, the radius is the height above it
    np.testing.assert_allclose(np.sort(np.unique(v[:, 0].round(9))), sorted({p[0] for p in CURVE}))
    radius = np.repeat([p[1] + 1 for p in CURVE], 12)
    np.testing.assert_allclose(np.hypot(v[:, 1] + 1, v[:, 2]), radius, rtol=1e-5)  # OBJ: 6 digits


def test_stl_is_binary_with_the_same_triangles(client):
    obj = client.post("/revolve", json={"curve": VASE, "segments": 16})
    r = client.post("/revolve", json={"curve": VASE, "segments": 16, "format": "stl"})
    assert r.status_code == 200 and r.headers["content-type"] == "model/stl"
    assert r.headers["content-disposition"] == 'attachment; filename="surface.stl"'
    n = int.from_bytes(r.content[80:84], "little")
    assert n == int(obj.headers["x-mesh-faces"]) and len(r.content) == 84 + 50 * n


@pytest.mark.parametrize(
    "body,detail",
    [
        pytest.param(
            {"curve": CURVE, "axis_position": 4}, "curve: profile crosses the axis (point 0", id="crossing-the-axis"
        ),
        pytest.param({"curve": CURVE, "segments": 2}, "segments: Input should be greater than or equal to 3", id="seg"),
        pytest.param({"curve": CURVE, "axis": "z"}, "axis: Input should be 'x' or 'y'", id="axis"),
        pytest.param({"curve": CURVE, "format": "ply"}, "format: Input should be 'obj' or 'stl'", id="format"),
        pytest.param({"curve": CURVE[:3]}, "curve: List should have at least 4 items", id="short-profile"),
        pytest.param(
            {"curve": [[0, 0], [0, 1], [0, 2], [0, 3]], "axis_position": 0},
            "curve: the profile lies on the axis",
            id="profile-on-the-axis",
        ),
    ],
)
def test_revolve_rejects_what_it_cannot_revolve(client, body, detail):
    r = client.post("/revolve", json=body)
    assert r.status_code == 422, r.text
    assert r.json()["detail"].startswith(detail), r.json()["detail"]


def test_mesh_size_limit(make_client):
    client = make_client(max_mesh_triangles=1000)
    assert client.post("/revolve", json={"curve": CURVE, "segments": 83}).status_code == 200  # 996 triangles
    r = client.post("/revolve", json={"curve": CURVE, "segments": 84})
    assert r.status_code == 422
    assert r.json()["detail"] == (
        "segments: 84 segments of a 7-point profile make up to 1008 triangles; "
        "at most 1000 (CURVE_VAE_MAX_MESH_TRIANGLES)"
    )
