"""The Open Inference Protocol's routes under /v2 (service.routes.oip): health, readiness and metadata from the graphs,
an unknown model's 404, inference through the same queue as every model route, binary tensors refused."""

from __future__ import annotations

import numpy as np
import onnxruntime as ort
import pytest
from fastapi.testclient import TestClient

from curve_vae.service.app import create_app
from curve_vae.service.settings import Settings
from tests.helpers import bspline_curves

DATATYPE = {"tensor(float)": "FP32"}


def graph_tensors(path) -> dict[str, list[dict]]:
    """What onnxruntime says of a graph's tensors, in the protocol's terms (-1 for a symbolic axis)."""
    session = ort.InferenceSession(str(path), providers=["CPUExecutionProvider"])
    return {
        kind: [
            {"name": t.name, "datatype": DATATYPE[t.type], "shape": [d if isinstance(d, int) else -1 for d in t.shape]}
            for t in tensors
        ]
        for kind, tensors in (("inputs", session.get_inputs()), ("outputs", session.get_outputs()))
    }


def tensor(name: str, a: np.ndarray, datatype: str = "FP32") -> dict:
    return {"name": name, "shape": list(a.shape), "datatype": datatype, "data": a.ravel().tolist()}


def encoder_request(count: int = 2, seed: int = 0) -> dict:
    return {"inputs": [tensor("curves", bspline_curves(count, seed=seed).astype(np.float32))]}


def error(r, status: int = 400) -> str:
    assert r.status_code == status, r.text
    assert set(r.json()) == {"error"}, r.text
    return r.json()["error"]


def test_health_and_readiness(client):
    assert client.get("/v2/health/live").json() == {"live": True}
    assert client.get("/v2/health/ready").json() == {"ready": True}
    for model in ("encoder", "decoder"):
        assert client.get(f"/v2/models/{model}/ready").json() == {"name": model, "ready": True}
    server = client.get("/v2").json()
    assert server["name"] == "curve-vae" and server["extensions"] == []


def test_not_ready_before_the_model_is_loaded(model_dir):
    client = TestClient(create_app(Settings(model_dir=model_dir)))  # no `with`: the lifespan never loads the model
    assert client.get("/v2/health/live").status_code == 200
    assert "not loaded" in error(client.get("/v2/health/ready"), 503)
    assert "not loaded" in error(client.get("/v2/models/encoder/ready"), 503)
    assert "not loaded" in error(client.post("/v2/models/decoder/infer", json={"inputs": []}), 503)


@pytest.mark.parametrize("model", ["encoder", "decoder"])
def test_metadata_is_the_graphs_own(client, model_dir, runtime, model):
    meta = client.get(f"/v2/models/{model}").json()
    assert meta["name"] == model and meta["platform"] == "onnxruntime_onnx"
    assert meta["versions"] == [runtime.manifest.version]
    graph = graph_tensors(model_dir / f"{model}.onnx")
    assert {"inputs": meta["inputs"], "outputs": meta["outputs"]} == graph
    assert all(t["shape"][0] == -1 for t in graph["inputs"] + graph["outputs"])  # the batch axis


def test_infer_goes_through_the_inference_queue(make_client):
    client = make_client()
    assert client.post("/v2/models/encoder/infer", json=encoder_request(3)).status_code == 200
    text = client.get("/metrics").text
    assert 'curve_vae_batch_size_sum{route="/v2/models/encoder/infer"} 3.0' in text
    assert 'curve_vae_inference_duration_seconds_count{route="/v2/models/encoder/infer"} 1.0' in text
    assert 'route="/v2/models/encoder/infer",status="200"' in text


def test_binary_tensor_data_is_refused_with_what_to_send_instead(client):
    r = client.post("/v2/models/encoder/infer", content=b"{}", headers={"Inference-Header-Content-Length": "2"})
    assert "binary_data=False" in error(r)


@pytest.mark.parametrize(
    ("method", "path"),
    [("get", "/v2/models/resnet"), ("get", "/v2/models/resnet/ready"), ("post", "/v2/models/resnet/infer")],
)
def test_an_unknown_model_is_404(client, method, path):
    r = getattr(client, method)(path, **({"json": encoder_request(1)} if method == "post" else {}))
    assert error(r, 404) == "unknown model 'resnet': this server serves encoder and decoder"
