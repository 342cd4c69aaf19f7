"""JSON in and out with orjson (service.routing): bodies orjson refuses (NaN, Infinity) still read by the stdlib so
that the schema names the point; and numbers written back at the precision the routes mean (float64 as float64, the
encoder's float32 means exactly)."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from curve_vae.service.routing import JSON, loads


@pytest.mark.parametrize(
    ("body", "expected"),
    [
        pytest.param(b'{"a": [1, 2.5, "x", null, true]}', {"a": [1, 2.5, "x", None, True]}, id="json"),
        pytest.param(b"[1e308, -0.0]", [1e308, -0.0], id="large-and-signed-zero"),
    ],
)
def test_loads_reads_json(body, expected):
    assert loads(body) == expected


@pytest.mark.parametrize(
    ("body", "check"),
    [
        pytest.param(b"[NaN]", lambda v: math.isnan(v[0]), id="nan"),
        pytest.param(b"[Infinity, -Infinity]", lambda v: v == [math.inf, -math.inf], id="infinity"),
    ],
)
def test_loads_falls_back_to_the_stdlib_for_what_orjson_refuses(body, check):
    assert check(loads(body))


def test_loads_raises_the_stdlibs_error_on_what_neither_reads():
    with pytest.raises(json.JSONDecodeError):
        loads(b'{"curves": [1, 2')


@pytest.mark.parametrize(
    ("literal", "loc"),
    [
        pytest.param("NaN", "curves[0][2][0]", id="nan"),
        pytest.param("-Infinity", "curves[0][2][0]", id="minus-infinity"),
    ],
)
def test_a_non_finite_literal_gets_the_schemas_message_with_its_point(client, literal, loc):
    body = f'{{"curves": [[[0, 0], [1, 2], [{literal}, 3], [3, 1]]]}}'.encode()
    r = client.post("/reconstruct", content=body, headers={"Content-Type": "application/json"})
    assert r.status_code == 422 and r.json()["detail"] == f"{loc}: not a finite number"


def test_the_response_renders_numpy_arrays_and_non_string_keys():
    out = JSON({"a": np.arange(6, dtype=np.float64).reshape(2, 3) / 4, 1: np.float32(0.1)}).body
    assert json.loads(out) == {"a": [[0.0, 0.25, 0.5], [0.75, 1.0, 1.25]], "1": pytest.approx(0.1, abs=1e-8)}


def test_encode_returns_the_encoders_float32_means_exactly(client, runtime, curves):
    """The means are float32 numbers written as float64 (their exact value): each one read back and turned into a
    float32 is unchanged, and equals the runtime's mean to the last bit."""
    from curve_vae.inference.reading import Reading

    c = curves(3, 90)
    body = client.post("/encode", json={"curves": c.tolist(), "pose": "as_is", "spacing": "parameter"}).json()
    mean = np.array(body["mean"], dtype=np.float64)
    assert np.array_equal(mean.astype(np.float32).astype(np.float64), mean)  # float32 values, written in full
    expected = runtime.encode(list(c), Reading(pose="as_is", spacing="parameter")).mean
    assert np.array_equal(mean, np.asarray(expected, dtype=np.float64))
