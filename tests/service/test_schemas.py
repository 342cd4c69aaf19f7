"""The v1 request bodies (service.schemas), by what a client sees: which fields each request takes and requires,
their defaults and documentation in the OpenAPI document, and the rule that combines two fields (steps or weights)."""

from __future__ import annotations

import pytest


def test_steps_and_weights_exclude_each_other_even_as_null(client):
    c = [[0, 0], [1, 2], [2, 3], [3, 1]]
    r = client.post("/interpolate", json={"curves": [c, c[::-1]], "steps": 3, "weights": None})
    assert r.status_code == 422 and "either steps or weights" in r.json()["detail"]


C1 = [[0, 0], [1, 2], [2.5, 3.2], [4, 3.5], [5.5, 3], [7, 1.5], [8, 0]]
C2 = [[0, 0], [1.5, 0.5], [3, 2], [4, 4], [5, 6.5], [6.5, 8], [8, 8.5]]
C3 = [[0, 4], [2, 5], [4, 4], [6, 2], [8, 1], [10, 2], [12, 4]]

#: Each v1 route, its request schema and a minimal valid body (seeded where the answer is random).
ROUTES = [
    pytest.param("/encode", "EncodeRequest", {"curves": [C1]}, id="encode"),
    pytest.param("/reconstruct", "ReconstructRequest", {"curves": [C1, C2]}, id="reconstruct"),
    pytest.param("/decode", "DecodeRequest", {"latents": [[0.1] * 32]}, id="decode"),
    pytest.param("/interpolate", "InterpolateRequest", {"curves": [C1, C2], "steps": 3}, id="interpolate"),
    pytest.param("/sample", "SampleRequest", {"count": 2, "seed": 4}, id="sample"),
    pytest.param("/augment", "AugmentRequest", {"curves": [C1, C2, C3], "count": 3, "seed": 4}, id="augment"),
    pytest.param("/fit", "FitRequest", {"curves": [C1]}, id="fit"),
    pytest.param("/revolve", "RevolveRequest", {"curve": C3}, id="revolve"),
]


@pytest.fixture(scope="module")
def schemas(model_dir, runtime) -> dict:
    from fastapi.testclient import TestClient

    from curve_vae.service.app import create_app
    from curve_vae.service.settings import Settings

    with TestClient(create_app(Settings(model_dir=model_dir), runtime=runtime)) as client:
        return client.get("/openapi.json").json()["components"]["schemas"]


@pytest.mark.parametrize(("path", "name", "body"), ROUTES)
def test_an_empty_body_is_told_every_required_field_and_only_those(client, schemas, path, name, body):
    required = schemas[name]["required"]
    r = client.post(path, json={})
    assert r.status_code == 422
    assert sorted(e["loc"] for e in r.json()["errors"]) == sorted(required)
    assert all(e["msg"] == "field required" for e in r.json()["errors"])
    assert set(required) <= set(body)  # the minimal bodies below hold them


@pytest.mark.parametrize(("path", "name", "body"), ROUTES)
def test_the_documented_defaults_are_the_ones_applied(client, schemas, path, name, body):
    """A request that spells out every default the OpenAPI document states gets the same answer as one that omits
    them; and every field of the request is documented."""
    props = schemas[name]["properties"]
    assert all(p.get("description") for p in props.values()), [k for k, p in props.items() if not p.get("description")]
    defaults = {k: p["default"] for k, p in props.items() if "default" in p and k not in body}
    assert defaults, name
    plain, spelt = client.post(path, json=body), client.post(path, json={**body, **defaults})
    assert plain.status_code == spelt.status_code == 200, (plain.text, spelt.text)
    assert plain.content == spelt.content


def test_decode_and_reconstruct_default_to_different_spacings_as_documented(client, schemas):
    """/decode's spacing defaults to "parameter" (the model's own points), /reconstruct's to "auto": a decode asked
    for "arc_length" differs from the default one, which is the "parameter" one."""
    assert schemas["DecodeRequest"]["properties"]["spacing"]["default"] == "parameter"
    assert schemas["ReconstructRequest"]["properties"]["spacing"]["default"] == "auto"
    z = {"latents": [[0.3] * 32], "n_points": 40}
    default = client.post("/decode", json=z).json()["curves"]
    assert client.post("/decode", json={**z, "spacing": "parameter"}).json()["curves"] == default
    assert client.post("/decode", json={**z, "spacing": "arc_length"}).json()["curves"] != default
