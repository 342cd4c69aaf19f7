"""The Open Inference Protocol's request schemas in the OpenAPI document (service.oip_docs): the tensors of the loaded
model (or the shipped model's before one is loaded), and a schema that accepts what the server accepts and refuses
what it refuses."""

from __future__ import annotations

import jsonschema
import numpy as np
import onnxruntime as ort
import pytest

from curve_vae.service import oip
from tests.helpers import SHIPPED

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


def _curves(batch: int, points: int = 161) -> list[float]:
    return np.zeros((batch, points, 2), np.float32).ravel().tolist()


def _encoder(**change) -> dict:
    tensor = {"name": "curves", "shape": [2, 161, 2], "datatype": "FP32", "data": _curves(2)}
    return {"inputs": [{**tensor, **change}]}


AGREE = [
    pytest.param(_encoder(), True, id="valid"),
    pytest.param({**_encoder(), "id": "a", "outputs": [{"name": "mean"}]}, True, id="valid-one-output"),
    pytest.param(_encoder(shape=[0, 161, 2], data=[]), False, id="batch-0"),
    pytest.param(_encoder(shape=[4, 161, 2], data=_curves(4)), False, id="batch-over-max-curves"),
    pytest.param(_encoder(shape=[2, 160, 2], data=_curves(2, 160)), False, id="wrong-point-count"),
    pytest.param(_encoder(datatype="FP64"), False, id="wrong-datatype"),
    pytest.param(_encoder(name="points"), False, id="wrong-name"),
    pytest.param({**_encoder(), "outputs": [{"name": "latent"}]}, False, id="unknown-output"),
    pytest.param({**_encoder(), "extra": 1}, False, id="unknown-field"),
    pytest.param({"inputs": []}, False, id="no-inputs"),
]


@pytest.mark.parametrize(("body", "valid"), AGREE)
def test_the_stated_schema_accepts_what_the_server_accepts(make_client, body, valid):
    client = make_client(max_curves=3)
    op = client.get("/openapi.json").json()["paths"]["/v2/models/encoder/infer"]["post"]
    schema = op["requestBody"]["content"]["application/json"]["schema"]
    errors = list(jsonschema.Draft202012Validator(schema).iter_errors(body))
    r = client.post("/v2/models/encoder/infer", json=body)
    assert (not errors) == valid, errors
    assert r.status_code == (200 if valid else 400), r.text


@pytest.mark.parametrize("model", ["encoder", "decoder"])
def test_the_stated_examples_are_answered(client, model):
    op = client.get("/openapi.json").json()["paths"][f"/v2/models/{model}/infer"]["post"]
    examples = op["requestBody"]["content"]["application/json"]["examples"]
    metadata = client.get(f"/v2/models/{model}").json()
    for name, example in examples.items():
        r = client.post(f"/v2/models/{model}/infer", json=example["value"])
        assert r.status_code == 200, (name, r.text)
        wanted = [o["name"] for o in example["value"].get("outputs", [])] or [o["name"] for o in metadata["outputs"]]
        assert [o["name"] for o in r.json()["outputs"]] == wanted
