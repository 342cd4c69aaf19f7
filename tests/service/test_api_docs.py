"""What the OpenAPI page shows beyond the schemas (service.api_docs): every request example is accepted as it stands,
each error example is the answer the service gives to that error, and the curl samples are runnable commands."""

from __future__ import annotations

import shlex

from curve_vae.service.openapi import openapi_spec


def test_request_examples_are_valid_requests(client):
    """Every example body in the schema is accepted by the running app."""
    for path, item in openapi_spec()["paths"].items():
        op = item.get("post")
        if op is None:
            continue
        for name, example in op["requestBody"]["content"]["application/json"]["examples"].items():
            r = client.post(path, json=example["value"])
            assert r.status_code == 200, (path, name, r.text)


def _error_example(spec: dict, path: str, code: str) -> dict:
    return spec["paths"][path]["post"]["responses"][code]["content"]["application/json"]["example"]


def test_the_422_example_is_the_answer_to_a_nan_at_that_point(client):
    """The documented 422 names curves[0][3][1]: a NaN there gets exactly that body."""
    example = _error_example(openapi_spec(), "/encode", "422")
    body = b'{"curves": [[[0, 0], [1, 2], [2, 3], [3, NaN]]]}'
    r = client.post("/encode", content=body, headers={"Content-Type": "application/json"})
    assert r.status_code == 422 and r.json() == example


def test_the_413_example_is_the_answer_to_a_body_of_that_size(make_client):
    """The documented 413 is for 9,000,000 bytes against the default limit (8 MiB): that body gets exactly it."""
    example = _error_example(openapi_spec(), "/reconstruct", "413")
    client = make_client()  # the default CURVE_VAE_MAX_BODY_BYTES
    r = client.post("/reconstruct", content=b" " * 9_000_000, headers={"Content-Type": "application/json"})
    assert r.status_code == 413 and r.json() == example


def test_the_503_example_is_the_answer_before_the_model_is_loaded(model_dir):
    from fastapi.testclient import TestClient

    from curve_vae.service.app import create_app
    from curve_vae.service.settings import Settings

    example = _error_example(openapi_spec(), "/reconstruct", "503")
    client = TestClient(create_app(Settings(model_dir=model_dir)))  # lifespan not run: no model
    r = client.post("/reconstruct", json={"curves": [[[0, 0], [1, 2], [2, 3], [3, 1]]]})
    assert r.status_code == 503 and r.json() == example


def test_the_401_example_says_what_the_service_says(make_client):
    example = _error_example(openapi_spec(), "/reconstruct", "401")
    r = make_client(api_keys=["k-0123456789"]).post("/reconstruct", json={"curves": []})
    assert r.status_code == 401 and r.json()["detail"] == example["detail"]


def test_the_401_example_is_the_whole_answer(make_client):
    example = _error_example(openapi_spec(), "/reconstruct", "401")
    r = make_client(api_keys=["k-0123456789"]).post("/reconstruct", json={"curves": []})
    assert r.json() == example


def test_every_curl_sample_posts_its_operations_own_example_shape(client):
    """Each POST's curl sample, run through the app instead of curl: its body (the text after -d) is accepted."""
    samples = 0
    for path, item in openapi_spec()["paths"].items():
        op = item.get("post")
        if op is None or "x-codeSamples" not in op:
            continue
        source = op["x-codeSamples"][0]["source"]
        assert source.startswith(f"curl -s http://127.0.0.1:8000{path}"), source
        parts = shlex.split(source)
        if "-d" not in parts or parts[parts.index("-d") + 1].startswith("@"):
            continue  # a body from a file (the protocol's tensors)
        assert parts[parts.index("-H") + 1] == "Content-Type: application/json", source
        r = client.post(path, content=parts[parts.index("-d") + 1], headers={"Content-Type": "application/json"})
        assert r.status_code == 200, (path, r.text)
        samples += 1
    assert samples >= 8  # encode, decode, reconstruct, interpolate, sample, augment, fit, revolve
