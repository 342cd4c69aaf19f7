"""Every endpoint through TestClient: shapes, frames and lengths over JSON, readiness, metadata, metrics, CORS."""

from __future__ import annotations

import numpy as np
import pytest
from fastapi.testclient import TestClient

from curve_vae.geometry import fit_frame, mse_per_curve
from curve_vae.inference.manifest import ModelLoadError
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


def test_encode_then_decode_in_the_returned_frames_is_the_reconstruction(client, curves):
    c = (curves(2) * 3 - 11).tolist()  # read as given (spacing "parameter"): the returned points are the model's
    enc = client.post("/encode", json={"curves": c, "spacing": "parameter"}).json()
    dec = client.post("/decode", json={"latents": enc["mean"], "frames": enc["frames"]}).json()
    rec = client.post("/reconstruct", json={"curves": c, "spacing": "parameter"}).json()
    np.testing.assert_allclose(dec["curves"], rec["curves"], rtol=1e-6, atol=1e-6)


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


def test_health_ready_model(client, model_dir):
    assert client.get("/health").json() == {"status": "ok"}
    assert client.get("/ready").json() == {"status": "ready"}
    info = client.get("/model").json()
    assert info["latent_dim"] == 32 and info["n_points"] == 161 and info["model_size"] == 100.0
    assert info["providers"] == ["CPUExecutionProvider"]
    manifest_sha = __import__("json").loads((model_dir / "manifest.json").read_text())["files"]["encoder.onnx"][
        "sha256"
    ]
    assert info["files"]["encoder.onnx"]["sha256"] == manifest_sha
    assert info["limits"]["max_curves"] == Settings().max_curves


def test_not_ready_before_the_model_is_loaded(model_dir):
    client = TestClient(create_app(Settings(model_dir=model_dir)))  # lifespan not run: nothing loaded
    assert client.get("/health").status_code == 200
    r = client.get("/ready")
    assert r.status_code == 503 and "not loaded" in r.json()["detail"]
    assert client.post("/encode", json={"curves": [CURVE]}).status_code == 503
    assert client.get("/model").status_code == 503


def test_the_lifespan_loads_the_model_and_fails_loudly(make_client, tmp_path):
    client = make_client(share_runtime=False, providers="cpu")
    assert client.get("/ready").status_code == 200
    with pytest.raises(ModelLoadError, match="manifest.json is missing"):
        with TestClient(create_app(Settings(model_dir=tmp_path))):
            pass


def test_metrics(client, curves):
    client.post("/encode", json={"curves": curves(3).tolist()})
    client.post("/encode", json={"curves": [[[0, 0]]]})
    client.get("/nowhere")
    text = client.get("/metrics").text
    assert 'curve_vae_http_requests_total{method="POST",route="/encode",status="200"} 1.0' in text
    assert 'curve_vae_http_requests_total{method="POST",route="/encode",status="422"} 1.0' in text
    assert 'curve_vae_http_requests_total{method="GET",route="unmatched",status="404"} 1.0' in text
    assert 'curve_vae_batch_size_bucket{le="4.0",route="/encode"} 1.0' in text
    assert 'curve_vae_http_request_duration_seconds_count{method="POST",route="/encode"} 2.0' in text
    assert "curve_vae_inference_duration_seconds_count" in text and "curve_vae_ready 1.0" in text


def test_metrics_are_per_app(make_client):
    a, b = make_client(), make_client()
    a.get("/health")
    assert 'route="/health"' not in b.get("/metrics").text


def test_cors_off_by_default_and_a_preflight_is_told_how_to_allow_its_origin(client):
    r = client.options("/encode", headers={"Origin": "https://app.example", "Access-Control-Request-Method": "POST"})
    assert r.status_code == 403 and "access-control-allow-origin" not in r.headers
    assert r.json()["detail"] == (
        "origin: calls from https://app.example are not allowed (the server allows no other origin): start it with "
        "--cors-origins https://app.example or CURVE_VAE_CORS_ORIGINS=https://app.example"
    )
    assert client.options("/encode").status_code == 405  # not a preflight: the routes' own answer


def test_cors_allows_configured_origins(make_client):
    client = make_client(cors_origins="https://app.example, https://other.example")
    pre = {"Access-Control-Request-Method": "POST", "Access-Control-Request-Headers": "content-type"}
    r = client.options("/encode", headers={"Origin": "https://app.example", **pre})
    assert r.status_code == 200 and r.headers["access-control-allow-origin"] == "https://app.example"
    r = client.post("/encode", json={"curves": [CURVE]}, headers={"Origin": "https://other.example"})
    assert r.headers["access-control-allow-origin"] == "https://other.example"
    r = client.options("/encode", headers={"Origin": "https://evil.example", **pre})
    assert r.status_code == 403 and "access-control-allow-origin" not in r.headers
    assert "CURVE_VAE_CORS_ORIGINS=https://app.example,https://other.example,https://evil.example" in r.json()["detail"]


def test_settings_from_environment(monkeypatch):
    monkeypatch.setenv("CURVE_VAE_PORT", "9123")
    monkeypatch.setenv("CURVE_VAE_PROVIDERS", "cpu")
    monkeypatch.setenv("CURVE_VAE_CORS_ORIGINS", '["https://a.example"]')
    monkeypatch.setenv("CURVE_VAE_MAX_CURVES", "7")
    s = Settings()
    assert (s.port, s.providers, s.cors_origins, s.max_curves) == (9123, "cpu", ["https://a.example"], 7)


def test_sample_is_reproducible_with_a_seed(client, runtime):
    a = client.post("/sample", json={"count": 3, "seed": 5, "n_points": 50}).json()
    b = client.post("/sample", json={"count": 3, "seed": 5, "n_points": 50}).json()
    c = client.post("/sample", json={"count": 3, "seed": 6, "n_points": 50}).json()
    assert a == b and a["latents"] != c["latents"]
    assert np.shape(a["latents"]) == (3, 32) and np.shape(a["curves"]) == (3, 50, 2)
    np.testing.assert_allclose(a["curves"], runtime.decode(np.array(a["latents"]), n_points=50).curves, rtol=1e-9)
    cold = client.post("/sample", json={"count": 2, "temperature": 0, "prior": "standard", "valid": False}).json()
    assert np.all(np.array(cold["latents"]) == 0)
    cold = client.post("/sample", json={"count": 4, "temperature": 0, "valid": False}).json()  # the learned prior
    for z in cold["latents"]:  # each a component's mean
        assert np.abs(runtime.prior.means - np.array(z)).max(axis=1).min() < 1e-12


@pytest.mark.parametrize("mode,k", [("pair", 2), ("triplet", 3)])
def test_augment(client, curves, runtime, mode, k):
    c = [x * (i + 1) + 10 * i for i, x in enumerate(curves(4, 161))]
    body = {"curves": [x.tolist() for x in c], "count": 6, "mode": mode, "seed": 3}
    out = client.post("/augment", json=body).json()
    assert out == client.post("/augment", json=body).json()  # same seed, same answer
    sources, weights = np.array(out["sources"]), np.array(out["weights"])
    assert sources.shape == weights.shape == (6, k)
    assert all(len(set(row)) == k for row in sources.tolist()) and sources.min() >= 0 and sources.max() < 4
    np.testing.assert_allclose(weights.sum(axis=1), 1.0)
    assert (weights >= 0).all()
    full = np.zeros((6, 4))
    np.put_along_axis(full, sources, weights, axis=1)
    expected = runtime.interpolate(c, full).curves
    np.testing.assert_allclose(out["curves"], expected, rtol=1e-9, atol=1e-9)


def test_the_shipped_model_is_served_by_default(shipped_runtime, curves):
    """Default settings serve models/; its checksums pass and it keeps the frame behaviour of item 3."""
    from curve_vae.inference.models import SHIPPED

    with TestClient(create_app(Settings(providers="cpu"))) as client:
        info = client.get("/model").json()
        assert info["name"] == shipped_runtime.manifest.name and info["version"] == shipped_runtime.manifest.version
        assert Settings().model_dir == SHIPPED
        c = curves(2, 75, seed=4)
        base = client.post("/reconstruct", json={"curves": c.tolist()}).json()
        moved = client.post("/reconstruct", json={"curves": (c * 0.01 - 7).tolist()}).json()
        np.testing.assert_allclose(
            np.array(moved["curves"]), np.array(base["curves"]) * 0.01 - 7, atol=1e-6 * 128 * 0.01
        )


def test_model_lists_only_the_files_the_directory_holds(model_dir, tmp_path):
    """An installed package ships no vae.pt (serving never reads it): GET /model lists what is there to read."""
    import json
    import shutil

    copy = tmp_path / "model"
    shutil.copytree(model_dir, copy)
    manifest = json.loads((copy / "manifest.json").read_text())
    manifest["files"]["vae.pt"] = {"sha256": "0" * 64, "bytes": 123}  # listed at export, left out of the wheel
    (copy / "manifest.json").write_text(json.dumps(manifest))
    with TestClient(create_app(Settings(model_dir=copy, providers="cpu"))) as client:
        info = client.get("/model").json()
    assert set(info["files"]) == {"encoder.onnx", "decoder.onnx", "prior.npz"}
    assert info["reading"] == {"pose": "search", "spacing": "search"}  # exported before readings were recorded
