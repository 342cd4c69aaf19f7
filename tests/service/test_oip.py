"""The Open Inference Protocol (KServe v2) under /v2: metadata from the graphs, infer equal to the runtime's own
runs, the protocol's request and response shapes, and its `{"error": ...}` answers."""

from __future__ import annotations

import json

import numpy as np
import onnxruntime as ort
import pytest
from fastapi.testclient import TestClient

from curve_vae.service import oip
from curve_vae.service.app import create_app
from curve_vae.service.settings import Settings
from tests.helpers import SHIPPED, bspline_curves

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


def outputs_of(body: dict) -> dict[str, np.ndarray]:
    return {o["name"]: np.array(o["data"], np.float32).reshape(o["shape"]) for o in body["outputs"]}


def error(r, status: int = 400) -> str:
    assert r.status_code == status, r.text
    assert set(r.json()) == {"error"}, r.text
    return r.json()["error"]


# ------------------------------------------------------------------------------------------- health and metadata


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


def test_the_schema_without_a_model_states_the_shipped_models_tensors():
    """openapi.yaml is written without loading a model: its tensors (oip.DEFAULT_SIGNATURES) are the shipped ones."""
    if not (SHIPPED / "manifest.json").is_file():
        pytest.skip("no shipped model")
    for model, sig in oip.DEFAULT_SIGNATURES.items():
        graph = graph_tensors(SHIPPED / f"{model}.onnx")
        assert [t.json() for t in sig.inputs] == graph["inputs"], model
        assert [t.json() for t in sig.outputs] == graph["outputs"], model


def test_the_live_schema_states_the_loaded_models_tensors(make_client, runtime):
    spec = make_client(max_curves=9).get("/openapi.json").json()
    body = spec["paths"]["/v2/models/decoder/infer"]["post"]["requestBody"]["content"]["application/json"]["schema"]
    latent = body["properties"]["inputs"]["items"]["properties"]
    assert latent["name"]["enum"] == ["latent"] and latent["datatype"]["enum"] == ["FP32"]
    assert latent["shape"]["prefixItems"] == [
        {"type": "integer", "minimum": 1, "maximum": 9},
        {"type": "integer", "const": runtime.latent_dim},
    ]
    assert body["properties"]["outputs"]["items"]["properties"]["name"]["enum"] == ["curves", "control_points"]
    assert {"/v2", "/v2/health/live", "/v2/health/ready", "/v2/models/encoder", "/v2/models/encoder/ready"} <= set(
        spec["paths"]
    )


# ------------------------------------------------------------------------------------------- infer


def test_encoder_then_decoder_equals_the_runtime(client, runtime):
    curves = bspline_curves(3, seed=4).astype(np.float32)
    r = client.post("/v2/models/encoder/infer", json={"id": "a-1", "inputs": [tensor("curves", curves)]})
    assert r.status_code == 200, r.text
    body = r.json()
    assert body["model_name"] == "encoder" and body["model_version"] == runtime.manifest.version
    assert body["id"] == "a-1"
    assert [(o["name"], o["datatype"], o["shape"]) for o in body["outputs"]] == [
        ("mean", "FP32", [3, runtime.latent_dim]),
        ("log_var", "FP32", [3, runtime.latent_dim]),
    ]
    got = outputs_of(body)
    mean, log_var = runtime.graphs.encode(curves)
    np.testing.assert_allclose(got["mean"], mean, atol=1e-5)
    np.testing.assert_allclose(got["log_var"], log_var, atol=1e-5)

    r = client.post("/v2/models/decoder/infer", json={"inputs": [tensor("latent", got["mean"])]})
    assert r.status_code == 200, r.text
    assert "id" not in r.json()
    decoded = outputs_of(r.json())
    want_curves, want_ctrl, _ = runtime.graphs.decode(mean)
    np.testing.assert_allclose(decoded["curves"], want_curves, atol=1e-5)
    np.testing.assert_allclose(decoded["control_points"], want_ctrl, atol=1e-5)


def test_outputs_selection_order_and_repeats(client):
    req = encoder_request()
    only = client.post("/v2/models/encoder/infer", json={**req, "outputs": [{"name": "log_var"}]}).json()
    assert [o["name"] for o in only["outputs"]] == ["log_var"]
    both = client.post(
        "/v2/models/encoder/infer",
        json={**req, "outputs": [{"name": "log_var"}, {"name": "mean", "parameters": {"binary_data": False}}]},
    ).json()
    assert [o["name"] for o in both["outputs"]] == ["log_var", "mean"]
    assert both["outputs"][0]["data"] == only["outputs"][0]["data"]
    repeated = client.post("/v2/models/encoder/infer", json={**req, "outputs": [{"name": "mean"}, {"name": "mean"}]})
    assert [o["name"] for o in repeated.json()["outputs"]] == ["mean"]
    every = client.post("/v2/models/encoder/infer", json={**req, "outputs": []}).json()
    assert [o["name"] for o in every["outputs"]] == ["mean", "log_var"]


def test_nested_data_is_the_same_tensor_as_flat(client):
    curves = bspline_curves(2, seed=1).astype(np.float32)
    flat = client.post("/v2/models/encoder/infer", json={"inputs": [tensor("curves", curves)]}).json()
    nested = {"name": "curves", "shape": [2, 161, 2], "datatype": "FP32", "data": curves.tolist()}
    assert client.post("/v2/models/encoder/infer", json={"inputs": [nested]}).json() == flat
    ragged = {**nested, "data": [curves[0].tolist(), curves[1].tolist()[:-1]]}
    assert "nested lists must have the tensor's shape" in error(
        client.post("/v2/models/encoder/infer", json={"inputs": [ragged]})
    )


def test_a_batch_is_run_in_parts_of_batch_size(client, runtime):
    curves = bspline_curves(30, seed=2).astype(np.float32)
    want = runtime.graphs.encode(curves)[0]
    r = client.post("/v2/models/encoder/infer", json={"inputs": [tensor("curves", curves)]})
    np.testing.assert_allclose(outputs_of(r.json())["mean"], want, atol=1e-5)
    sig = oip.signature(runtime.graphs.encoder)
    req = oip.parse_request({"inputs": [tensor("curves", curves)]}, "encoder", sig, max_batch=40)
    parts = oip.infer(runtime.graphs.encoder, req, batch_size=7)  # 7 + 7 + 7 + 7 + 2 rows
    np.testing.assert_allclose(parts["mean"], want, atol=1e-5)


def test_infer_goes_through_the_inference_queue(make_client):
    client = make_client()
    assert client.post("/v2/models/encoder/infer", json=encoder_request(3)).status_code == 200
    text = client.get("/metrics").text
    assert 'curve_vae_batch_size_sum{route="/v2/models/encoder/infer"} 3.0' in text
    assert 'curve_vae_inference_duration_seconds_count{route="/v2/models/encoder/infer"} 1.0' in text
    assert 'route="/v2/models/encoder/infer",status="200"' in text


# ------------------------------------------------------------------------------------------- errors


def _with(field: str, value, req: dict | None = None) -> dict:
    req = req or encoder_request(1)
    return {"inputs": [{**req["inputs"][0], field: value}]}


@pytest.mark.parametrize(
    ("body", "message"),
    [
        (_with("name", "latent"), "inputs[0].name: unknown input tensor 'latent'; the encoder's inputs are curves"),
        (_with("datatype", "FP64"), 'inputs[0].datatype: "FP64", but curves is FP32'),
        (_with("datatype", "INT32"), 'inputs[0].datatype: "INT32", but curves is FP32'),
        (_with("shape", [1, 160, 2]), "inputs[0].shape: [1, 160, 2] does not fit curves's shape [-1, 161, 2]"),
        (_with("shape", [322]), "inputs[0].shape: [322] does not fit curves's shape [-1, 161, 2]"),
        (_with("shape", [0, 161, 2]), "inputs[0].shape: [0, 161, 2] has an empty or negative axis"),
        (_with("shape", [1, 161, 2.5]), "inputs[0].shape: expected a list of integers"),
        (_with("shape", [1, 161, "2"]), "inputs[0].shape: expected a list of integers"),
        (_with("shape", [2, 161, 2]), "inputs[0].data: 322 numbers, but shape [2, 161, 2] holds 644"),
        (_with("data", [1.0] * 321), "inputs[0].data: 321 numbers, but shape [1, 161, 2] holds 322"),
        (_with("data", [1.0] * 321 + [1e39]), "inputs[0].data[321]: 1e+39 is not a finite FP32 number"),
        (_with("data", ["1"] * 322), "inputs[0].data[0]: '1' is not a number"),
        (_with("data", [True] * 322), "inputs[0].data[0]: True is not a number"),
        (_with("data", 5), "inputs[0].data: expected a list of numbers, got int"),
        (_with("colour", "red"), "inputs[0].colour: unknown field"),
        (_with("name", {}), "inputs[0].name: expected a string, got {}"),
        (_with("datatype", None), "inputs[0].datatype: null, but curves is FP32"),
        ({**encoder_request(1), "outputs": [{"name": ["mean"]}]}, 'outputs[0].name: expected a string, got ["mean"]'),
        ({"inputs": [{"name": "curves", "shape": [1, 161, 2], "data": []}]}, "inputs[0].datatype: field required"),
        ({"inputs": []}, "inputs: expected a list of tensors (encoder's: curves)"),
        ({}, "body.inputs: field required"),
        ([], "body: expected a JSON object"),
        ({**encoder_request(1), "extra": 1}, "body.extra: unknown field"),
        ({**encoder_request(1), "id": 7}, "id: expected a string, got 7"),
        ({**encoder_request(1), "id": None}, "id: expected a string, got null"),
        ({**encoder_request(1), "outputs": None}, "outputs: expected a list"),
        ({**encoder_request(1), "parameters": []}, "body.parameters: expected a JSON object"),
        (
            {**encoder_request(1), "outputs": [{"name": "z"}]},
            "outputs[0].name: unknown output tensor 'z'; the encoder's outputs are mean, log_var",
        ),
        ({**encoder_request(1), "outputs": {"name": "mean"}}, "outputs: expected a list"),
        ({"inputs": encoder_request(1)["inputs"] * 2}, "inputs[1].name: input 'curves' given twice"),
    ],
)
def test_a_request_that_does_not_fit_the_model_is_400_naming_what_is_wrong(client, body, message):
    assert message in error(client.post("/v2/models/encoder/infer", json=body))


def test_decoder_errors_name_the_decoders_tensors(client, runtime):
    r = client.post(
        "/v2/models/decoder/infer", json={"inputs": [tensor("latent", np.zeros((1, runtime.latent_dim + 1)))]}
    )
    assert f"does not fit latent's shape [-1, {runtime.latent_dim}]" in error(r)
    r = client.post("/v2/models/decoder/infer", json={"inputs": [tensor("curves", np.zeros((1, 161, 2)))]})
    assert "unknown input tensor 'curves'; the decoder's inputs are latent" in error(r)


def test_non_finite_json_numbers_and_unreadable_bodies_are_400(client):
    body = '{"inputs": [{"name": "curves", "shape": [1, 161, 2], "datatype": "FP32", "data": [0' + ", 0" * 320
    for token in ("NaN", "Infinity", "-Infinity"):  # JSON has no such numbers, but Python's parser reads them
        r = client.post("/v2/models/encoder/infer", content=f"{body}, {token}]}}]}}")
        assert error(r) == f"inputs[0].data[321]: {float(token)!r} is not a finite FP32 number"
    huge = json.dumps(_with("data", [10**400] + [0] * 321))
    assert "beyond FP32 range" in error(client.post("/v2/models/encoder/infer", content=huge))
    assert "body: not JSON" in error(client.post("/v2/models/encoder/infer", content=b'{"inputs": ['))
    assert "body: not JSON" in error(client.post("/v2/models/encoder/infer", content=b"\xff\xfe"))


def test_non_finite_outputs_are_400_not_a_broken_response():
    class Blows:
        def run(self, names, feed):
            return [np.full((len(next(iter(feed.values()))), 32), np.inf, np.float32) for _ in names]

    sig = oip.DEFAULT_SIGNATURES["encoder"]
    req = oip.parse_request(encoder_request(2), "encoder", sig, max_batch=8)
    with pytest.raises(oip.OipError, match="mean is not finite for batch row 0: its input lies far outside"):
        oip.infer(Blows(), req, batch_size=64)  # type: ignore[arg-type]


def test_batches_over_max_curves_are_400(make_client):
    client = make_client(max_curves=2)
    r = client.post("/v2/models/encoder/infer", json=encoder_request(3))
    assert "inputs[0].shape: batch of 3; at most 2 per request (CURVE_VAE_MAX_CURVES)" in error(r)


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


def test_api_keys_body_limit_and_unknown_paths_answer_in_the_protocols_format(make_client):
    client = make_client(api_keys="s3cret", max_body_bytes=4096)
    assert "needs an API key" in error(client.post("/v2/models/encoder/infer", json=encoder_request(1)), 401)
    assert "needs an API key" in error(client.get("/v2/models/encoder"), 401)
    assert client.get("/v2/health/live").status_code == 200  # probes need no key
    assert client.get("/v2/health/ready").status_code == 200
    key = {"X-API-Key": "s3cret"}
    assert client.get("/v2/models/encoder", headers=key).status_code == 200
    big = client.post("/v2/models/encoder/infer", json=encoder_request(2), headers=key)  # ~12 kB
    assert "exceeds the limit of 4096 bytes" in error(big, 413)
    decoded = client.post(
        "/v2/models/decoder/infer", json={"inputs": [tensor("latent", np.zeros((1, 32)))]}, headers=key
    )
    assert decoded.status_code == 200
    assert error(client.get("/v2/models/encoder/versions/1", headers=key), 404) == "Not Found"
    assert client.get("/ready").json() == {"status": "ready"}  # the v1 routes keep their own format
    assert set(client.post("/decode", json={}, headers=key).json()) == {"detail", "errors"}


def test_integral_numbers_are_integers_in_a_shape(client):
    """JSON Schema (and so the published schema) counts 2.0 as an integer: the service does too."""
    assert client.post("/v2/models/encoder/infer", json=_with("shape", [1.0, 161, 2])).status_code == 200


def test_raw_tensors_are_what_the_rest_routes_send_in_the_model_plane(client, runtime):
    """/encode with frame "model" and spacing "parameter" at the model's point count, and /decode without frames,
    run the same graphs on the same tensors as /v2 (what docs/DEPLOYMENT.md tells a Triton client)."""
    curves = bspline_curves(2, seed=9)
    raw = outputs_of(client.post("/v2/models/encoder/infer", json={"inputs": [tensor("curves", curves)]}).json())
    rest = client.post("/encode", json={"curves": curves.tolist(), "frame": "model", "spacing": "parameter"}).json()
    np.testing.assert_allclose(rest["mean"], raw["mean"], atol=1e-5)
    np.testing.assert_allclose(rest["log_var"], raw["log_var"], atol=1e-5)
    decoded = outputs_of(
        client.post("/v2/models/decoder/infer", json={"inputs": [tensor("latent", raw["mean"])]}).json()
    )
    rest = client.post("/decode", json={"latents": raw["mean"].tolist()}).json()
    np.testing.assert_allclose(rest["curves"], decoded["curves"], atol=1e-4)
