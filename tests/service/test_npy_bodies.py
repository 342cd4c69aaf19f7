""".npy request bodies (Content-Type: application/x-npy) on /encode, /reconstruct and /interpolate: the same answers
as the JSON requests, the other fields from the query string, and a 422 naming what is wrong with a bad array."""

from __future__ import annotations

import io

import httpx
import numpy as np
import pytest

NPY = {"Content-Type": "application/x-npy"}


def npy(a: np.ndarray) -> bytes:
    buf = io.BytesIO()
    np.save(buf, a)
    return buf.getvalue()


@pytest.fixture
def limited(make_client):
    return make_client(max_curves=4, max_points=300)


@pytest.mark.parametrize("dtype", [np.float32, np.float64, ">f8"], ids=["float32", "float64", "big-endian"])
def test_reconstruct_answers_as_for_json(client, curves, dtype):
    a = curves(3, 40).astype(dtype)
    as_json = client.post("/reconstruct", json={"curves": a.astype(np.float64).tolist(), "pose": "as_is"})
    as_npy = client.post("/reconstruct?pose=as_is", content=npy(a), headers=NPY)
    assert as_json.status_code == as_npy.status_code == 200, as_npy.text
    assert as_npy.json() == as_json.json()


def test_query_fields_are_json_values_or_strings(client, curves):
    a = curves(2, 40)
    r = client.post("/reconstruct?n_points=50&output=both&metrics=true&frame=auto", content=npy(a), headers=NPY)
    assert r.status_code == 200, r.text
    body = r.json()
    assert np.asarray(body["curves"]).shape == (2, 50, 2) and len(body["splines"]) == 2 and len(body["metrics"]) == 2


def test_one_curve_as_a_two_dimensional_array(client, curves):
    a = curves(1, 30)
    r = client.post("/encode", content=npy(a[0]), headers=NPY)
    assert r.status_code == 200, r.text
    assert r.json() == client.post("/encode", json={"curves": a.tolist()}).json()


def test_interpolate_takes_weights_from_the_query(client, curves):
    a = curves(2, 40)
    r = client.post("/interpolate?weights=[[0.25,0.75]]", content=npy(a), headers=NPY)
    assert r.status_code == 200, r.text
    expected = client.post("/interpolate", json={"curves": a.tolist(), "weights": [[0.25, 0.75]]}).json()
    assert r.json() == expected
    r = client.post("/interpolate?steps=4", content=npy(a), headers=NPY)
    assert r.status_code == 200 and len(r.json()["curves"]) == 4


def _nan() -> np.ndarray:
    a = np.tile(np.linspace(0, 1, 8)[:, None], (2, 1, 2))
    a[1, 5, 0] = np.nan
    return a


LINE = np.stack([np.arange(6.0), np.arange(6.0) ** 2], axis=1)

BAD = [
    pytest.param("/reconstruct", b'{"curves": []}', "body: not a .npy file", id="not-npy"),
    pytest.param("/reconstruct", b"\x93NUMPY\x01\x00\x10\x00{'descr': junk}   \n", "body: a .npy header", id="header"),
    pytest.param("/encode", npy(np.zeros((2, 6, 2), np.int64)), "body: dtype <i8: send float32 or float64", id="int"),
    pytest.param("/encode", npy(np.zeros((2, 6, 3))), "body: shape (2, 6, 3): expected", id="shape"),
    pytest.param("/encode", npy(np.zeros((6,))), "body: shape (6,): expected", id="one-axis"),
    pytest.param(
        "/encode", npy(LINE[None])[:-8], "body: 88 bytes of data, the header's shape (1, 6, 2) needs 96", id="short"
    ),
    pytest.param("/encode", npy(_nan()), "curves[1][5][0]: not a finite number", id="nan"),
    pytest.param("/encode", npy(np.zeros((1, 5, 2))), "curves[0]: all 5 points coincide", id="coincide"),
    pytest.param("/encode", npy(np.zeros((1, 3, 2))), "curves: at least 4 points per curve, got 3", id="too-short"),
    pytest.param(
        "/encode", npy(np.tile(LINE, (5, 1, 1))), "curves: at most 4 curves per request, got 5", id="too-many"
    ),
    pytest.param("/encode", npy(np.zeros((1, 301, 2)) + LINE[:1]), "curves: at most 300 points", id="too-long"),
    pytest.param("/encode", npy(np.zeros((0, 6, 2))), "curves: no curves", id="empty"),
]


@pytest.mark.parametrize(("path", "body", "detail"), BAD)
def test_a_bad_array_is_a_422_naming_what_is_wrong(limited, path, body, detail):
    r = limited.post(path, content=body, headers=NPY)
    assert r.status_code == 422, r.text
    assert r.json()["detail"].startswith(detail), r.json()["detail"]


@pytest.mark.parametrize(
    ("query", "detail"),
    [
        pytest.param("n_points=many", "query.n_points", id="not-a-number"),
        pytest.param("pose=sideways", "query.pose", id="bad-choice"),
        pytest.param("colour=red", "query.colour", id="unknown-field"),
        pytest.param("n_points=100000", "n_points: at most 300", id="limit"),
    ],
)
def test_a_bad_query_field_is_a_422_naming_it(limited, query, detail):
    r = limited.post(f"/reconstruct?{query}", content=npy(LINE[None]), headers=NPY)
    assert r.status_code == 422, r.text
    assert detail in r.json()["detail"], r.json()["detail"]


def test_npy_bodies_over_a_socket(server_factory, model_dir, curves):
    """Through uvicorn: the same answer as the JSON request, and the body limit still applies."""
    server = server_factory("--model-dir", str(model_dir), "--providers", "cpu", "--max-body-bytes", "200000")
    server.wait_ready()
    a = curves(2, 40).astype(np.float32)
    with httpx.Client(base_url=server.url, timeout=30) as http:
        as_npy = http.post("/reconstruct?pose=as_is", content=npy(a), headers=NPY)
        as_json = http.post("/reconstruct", json={"curves": a.astype(np.float64).tolist(), "pose": "as_is"})
        assert as_npy.status_code == 200 and as_npy.json() == as_json.json()
        big = http.post("/encode", content=npy(np.zeros((300, 161, 2), np.float32)), headers=NPY)
        assert big.status_code == 413
