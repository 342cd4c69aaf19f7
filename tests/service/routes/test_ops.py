"""GET /health, /ready, /model and /metrics (service.routes.ops): liveness, readiness, what /model says of the model
directory, its spline head and the server's execution, and the graph gauges /metrics refreshes."""

from __future__ import annotations

from fastapi.testclient import TestClient

from curve_vae.service.app import create_app
from curve_vae.service.settings import Settings


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
    # exported before readings were recorded: the search, and the look again every reading has by default
    assert info["reading"] == {"pose": "search", "spacing": "search", "looks": 1, "refine": 0}


def test_model_info_names_the_spline_head(client):
    spline = client.get("/model").json()["spline"]
    assert spline["n_ctrl"] == 31 and spline["degree"] == 3 and len(spline["knots"]) == 35
    assert spline["learned_params"] is False and spline["placement"] == "index"


def test_model_info_tells_a_head_with_learned_parameters(params_model_dir, params_runtime):
    with TestClient(create_app(Settings(model_dir=params_model_dir), runtime=params_runtime)) as client:
        assert client.get("/model").json()["spline"]["learned_params"] is True


def test_metrics_can_be_switched_off(make_client):
    client = make_client(metrics=False)
    r = client.get("/metrics")
    assert r.status_code == 404 and "CURVE_VAE_METRICS=false" in r.json()["detail"]
    assert client.get("/health").status_code == 200


def _gauge(text: str, graph: str) -> float:
    key = f'curve_vae_graph_rows{{graph="{graph}"}} '
    return float(next(line for line in text.splitlines() if line.startswith(key))[len(key) :])


def test_metrics_report_the_rows_each_graph_has_run(client, curves):
    """One encoding per curve (pose "as_is", spacing "parameter", no look again), one decoding per latent: the gauges
    /metrics refreshes from the runtime move by exactly that (the runtime is shared, so by differences)."""
    before = client.get("/metrics").text
    one = {"pose": "as_is", "spacing": "parameter", "looks": 0}
    client.post("/encode", json={"curves": curves(3).tolist(), **one})
    client.post("/decode", json={"latents": [[0.0] * 32] * 5})
    after = client.get("/metrics").text
    assert _gauge(after, "encoder") - _gauge(before, "encoder") == 3
    assert _gauge(after, "decoder") - _gauge(before, "decoder") == 5


def test_model_states_this_servers_limits(make_client):
    limits = dict(max_curves=9, max_points=99, max_body_bytes=9999, max_stream_curves=999, max_mesh_triangles=99999)
    info = make_client(**limits, max_refine_work=12345).get("/model").json()
    assert info["limits"] == {**limits, "max_refine_work": 12345}


def test_model_reports_the_manifest_and_the_service_version(client, runtime):
    from curve_vae import __version__

    info = client.get("/model").json()
    m = runtime.manifest
    assert (info["name"], info["version"], info["service_version"]) == (m.name, m.version, __version__)
    assert info["requested_providers"] == "cpu" and info["cache"] is None  # the shared runtime has no cache
