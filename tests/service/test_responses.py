"""The v1 response bodies (inference.answers; service.responses for errors, status and GET /model): what each route
answers is what the OpenAPI page documents for it, every key documented and every documented type right (the real
answers validated against the published schema)."""

from __future__ import annotations

import jsonschema
import pytest

C1 = [[0, 0], [1, 2], [2.5, 3.2], [4, 3.5], [5.5, 3], [7, 1.5], [8, 0]]
C2 = [[0, 0], [1.5, 0.5], [3, 2], [4, 4], [5, 6.5], [6.5, 8], [8, 8.5]]
C3 = [[0, 4], [2, 5], [4, 4], [6, 2], [8, 1], [10, 2], [12, 4]]

CALLS = [
    pytest.param("post", "/encode", {"curves": [C1, C2]}, id="encode"),
    pytest.param("post", "/encode", {"curves": [C1], "frame": "model"}, id="encode-model-frame"),
    pytest.param("post", "/decode", {"latents": [[0.1] * 32], "output": "both", "metrics": True}, id="decode"),
    pytest.param("post", "/reconstruct", {"curves": [C1, C2], "output": "both", "metrics": True}, id="reconstruct"),
    pytest.param("post", "/interpolate", {"curves": [C1, C2], "steps": 3, "output": "bspline"}, id="interpolate"),
    pytest.param("post", "/sample", {"count": 2, "seed": 1, "metrics": True}, id="sample"),
    pytest.param("post", "/augment", {"curves": [C1, C2, C3], "count": 2, "seed": 1}, id="augment"),
    pytest.param("post", "/fit", {"curves": [C1], "n_ctrl": 5, "n_points": 10}, id="fit"),
    pytest.param("get", "/model", None, id="model"),
    pytest.param("get", "/health", None, id="health"),
    pytest.param("get", "/ready", None, id="ready"),
    pytest.param("post", "/reconstruct", {"curves": [[[0, 0]]]}, id="error-422"),
]


@pytest.fixture(scope="module")
def spec(model_dir, runtime) -> dict:
    from fastapi.testclient import TestClient

    from curve_vae.service.app import create_app
    from curve_vae.service.settings import Settings

    with TestClient(create_app(Settings(model_dir=model_dir), runtime=runtime)) as client:
        return client.get("/openapi.json").json()


def _undocumented(value, schema: dict, spec: dict, where: str = "") -> list[str]:
    """Keys of `value` that its schema does not name (pydantic's schemas allow extra keys; the API should send none)."""
    while "$ref" in schema:
        schema = spec["components"]["schemas"][schema["$ref"].rsplit("/", 1)[1]]
    for option in schema.get("anyOf", []):
        if option.get("type") != "null" and value is not None:
            return _undocumented(value, option, spec, where)
    out = []
    if isinstance(value, dict) and "properties" in schema:
        for key, item in value.items():
            if key not in schema["properties"]:
                out.append(f"{where}.{key}")
            else:
                out += _undocumented(item, schema["properties"][key], spec, f"{where}.{key}")
    elif isinstance(value, list) and isinstance(schema.get("items"), dict) and value:
        out += _undocumented(value[0], schema["items"], spec, f"{where}[0]")
    return out


@pytest.mark.parametrize(("method", "path", "body"), CALLS)
def test_each_answer_is_what_the_schema_documents(client, spec, method, path, body):
    r = client.post(path, json=body) if method == "post" else client.get(path)
    status = str(r.status_code)
    assert status in ("200", "422"), r.text
    schema = spec["paths"][path][method]["responses"][status]["content"]["application/json"]["schema"]
    resolver = {**schema, "components": spec["components"]}
    jsonschema.validate(r.json(), resolver, cls=jsonschema.Draft202012Validator)
    assert not _undocumented(r.json(), schema, spec)


def test_a_wrong_type_in_an_answer_would_be_caught(spec):
    """The check above can fail: an encode answer with a string for a mean is refused by the same schema."""
    schema = spec["paths"]["/encode"]["post"]["responses"]["200"]["content"]["application/json"]["schema"]
    bad = {"mean": [["0.1"]], "log_var": [[0.0]], "frames": None}
    with pytest.raises(jsonschema.ValidationError):
        jsonschema.validate(bad, {**schema, "components": spec["components"]}, cls=jsonschema.Draft202012Validator)
    assert _undocumented({**bad, "extra": 1}, schema, spec) == [".extra"]
