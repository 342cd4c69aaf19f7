"""The Open Inference Protocol (KServe v2) requests and answers (service.oip): infer equal to the runtime's own runs,
the protocol's request and response shapes, and its `{"error": ...}` answers to what does not fit the tensors."""

from __future__ import annotations

import json

import numpy as np
import pytest

from curve_vae.service import oip
from tests.helpers import bspline_curves


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
