"""The request body limit (service.middleware): a 413 that names the limit, by Content-Length or while a streamed
body is read; exactly the limit is accepted; over a socket, clients that send the whole body first, and curl, which
asks first."""

from __future__ import annotations

import json
import shutil
import subprocess

import httpx
import numpy as np
import pytest


def test_an_oversized_body_from_the_standard_library_client_gets_the_413(live_server):
    """urllib sends the whole body before it reads the answer: the server reads the rest and drops it, then answers."""
    import urllib.error
    import urllib.request

    body = json.dumps({"curves": [np.linspace(0, 1, 8000).reshape(-1, 2).tolist()] * 40}).encode()  # ~3 MB
    assert len(body) > 10 * 200_000  # far over the server's --max-body-bytes
    req = urllib.request.Request(
        f"{live_server.url}/encode", data=body, headers={"Content-Type": "application/json"}, method="POST"
    )
    with pytest.raises(urllib.error.HTTPError) as err:
        urllib.request.urlopen(req, timeout=30)
    assert err.value.code == 413
    assert "exceeds the limit of 200000 bytes" in json.loads(err.value.read())["detail"]
    assert httpx.get(f"{live_server.url}/health").status_code == 200


def test_an_oversized_body_after_expect_100_continue_is_refused_unread(live_server):
    """curl asks before sending a large body: the 413 comes at once and the body is never sent."""
    if shutil.which("curl") is None:
        pytest.skip("curl is not installed")
    out = subprocess.run(
        [
            "curl",
            "-s",
            "-o",
            "/dev/null",
            "-w",
            "%{http_code} %{size_upload}",
            "-H",
            "Content-Type: application/json",
            "-H",
            "Expect: 100-continue",
            "--data-binary",
            "@-",
            f"{live_server.url}/encode",
        ],
        input=b"[" + b"0," * 1_000_000 + b"0]",
        capture_output=True,
        timeout=30,
    )
    code, uploaded = out.stdout.decode().split()
    assert code == "413" and float(uploaded) < 2_000_000


C = [[0, 0], [1, 2], [2.5, 3.2], [4, 3.5], [5.5, 3], [7, 1.5], [8, 0]]  # a valid curve


LIMITS = {"max_curves": 4, "max_points": 300, "max_body_bytes": 20_000}


@pytest.fixture
def limited(make_client):
    return make_client(**LIMITS)


def test_body_over_the_limit_is_413(limited):
    big = {"curves": [np.linspace(0, 1, 600).reshape(300, 2).tolist()] * 4}
    r = limited.post("/reconstruct", json=big)
    assert r.status_code == 413
    assert r.json()["detail"].startswith("body: a body of") and "20000 bytes" in r.json()["detail"]


def test_streamed_body_over_the_limit_is_413(limited):
    def chunks():  # no Content-Length: the limit must hold while reading
        yield b'{"curves": ['
        for _ in range(100):
            yield json.dumps(C).encode() * 5 + b","
        yield b"]}"

    r = limited.post("/encode", content=chunks(), headers={"Content-Type": "application/json"})
    assert r.status_code == 413 and "streamed body" in r.json()["detail"]


def _body_of(size: int) -> bytes:
    """A valid /encode body of exactly `size` bytes (padded with spaces, which JSON ignores)."""
    body = json.dumps({"curves": [C]}).encode()
    assert len(body) <= size
    return body + b" " * (size - len(body))


@pytest.mark.parametrize(
    ("size", "status"),
    [pytest.param(20_000, 200, id="exactly-the-limit"), pytest.param(20_001, 413, id="one-byte-over")],
)
def test_the_limit_is_inclusive(limited, size, status):
    r = limited.post("/encode", content=_body_of(size), headers={"Content-Type": "application/json"})
    assert r.status_code == status, r.text
    if status == 413:
        assert r.json() == {
            "detail": "body: a body of 20001 bytes exceeds the limit of 20000 bytes (CURVE_VAE_MAX_BODY_BYTES)",
            "errors": [
                {
                    "loc": "body",
                    "msg": "a body of 20001 bytes exceeds the limit of 20000 bytes (CURVE_VAE_MAX_BODY_BYTES)",
                }
            ],
        }


@pytest.mark.parametrize(
    ("size", "status"),
    [pytest.param(20_000, 200, id="exactly-the-limit"), pytest.param(20_001, 413, id="one-byte-over")],
)
def test_a_streamed_body_is_held_to_the_same_limit(limited, size, status):
    body = _body_of(size)

    def chunks():  # no Content-Length: counted while read
        for i in range(0, len(body), 1000):
            yield body[i : i + 1000]

    r = limited.post("/encode", content=chunks(), headers={"Content-Type": "application/json"})
    assert r.status_code == status, r.text
    if status == 413:
        read = int(r.json()["detail"].split("at least ")[1].split()[0])  # counted up to the chunk that broke it
        assert 20000 < read <= min(size, 21000)
        limit = "exceeds the limit of 20000 bytes (CURVE_VAE_MAX_BODY_BYTES)"
        assert r.json()["detail"] == f"body: a streamed body of at least {read} bytes {limit}"


def test_a_body_within_the_limit_reaches_the_route_unchanged(limited, runtime):
    """The middleware reads the body and replays it: the route answers as for any request."""
    from curve_vae.inference.reading import Reading

    r = limited.post("/encode", content=_body_of(19_000), headers={"Content-Type": "application/json"})
    expected = runtime.encode([np.array(C, float)], Reading()).mean
    np.testing.assert_allclose(r.json()["mean"], expected, rtol=1e-6)
