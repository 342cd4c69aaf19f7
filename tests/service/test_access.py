"""API keys (service.middleware): every route but liveness and readiness needs one when keys are set."""

from __future__ import annotations

import pytest

from curve_vae.service.middleware import accepted, key_of

CURVE = [[0, 0], [1, 2], [2.5, 3.2], [4, 3.5], [5.5, 3], [7, 1.5], [8, 0]]
KEYS = ["k-one-0123456789", "k-two-abcdefghij"]


@pytest.fixture
def locked(make_client):
    return make_client(api_keys=KEYS, cors_origins=["https://app.example"])


@pytest.mark.parametrize(
    "headers",
    [
        pytest.param({"Authorization": "Bearer k-one-0123456789"}, id="bearer"),
        pytest.param({"X-API-Key": "k-two-abcdefghij"}, id="x-api-key"),
        pytest.param({"authorization": "bearer   k-two-abcdefghij  "}, id="bearer-case-and-spaces"),
    ],
)
def test_a_valid_key_opens_every_route(locked, headers):
    assert locked.post("/reconstruct", json={"curves": [CURVE]}, headers=headers).status_code == 200
    assert locked.get("/model", headers=headers).status_code == 200
    assert locked.get("/metrics", headers=headers).status_code == 200


@pytest.mark.parametrize(
    ("headers", "message"),
    [
        pytest.param(
            {}, "this service needs an API key: send Authorization: Bearer <key> or X-API-Key: <key>", id="none"
        ),
        pytest.param({"X-API-Key": "k-one-012345678"}, "the API key is not valid for this service", id="prefix"),
        pytest.param({"Authorization": "Basic k-one-0123456789"}, "this service needs an API key", id="basic"),
        pytest.param({"X-API-Key": ""}, "this service needs an API key", id="empty"),
    ],
)
def test_no_key_or_a_wrong_one_is_a_401_that_says_what_to_do(locked, headers, message):
    for method, path in [("post", "/encode"), ("get", "/model"), ("get", "/metrics"), ("post", "/fit")]:
        kwargs = {"json": {"curves": [CURVE]}} if method == "post" else {}
        r = getattr(locked, method)(path, headers=headers, **kwargs)
        assert r.status_code == 401, path
        assert r.json()["detail"].startswith(message) and r.headers["www-authenticate"] == "Bearer"
        assert "Traceback" not in r.text and "/" not in r.json()["detail"].split(":")[0]


def test_probes_the_page_and_preflights_need_no_key(locked):
    for path in ("/health", "/ready", "/", "/static/app.js", "/docs", "/openapi.json"):
        assert locked.get(path).status_code == 200, path
    preflight = locked.options(
        "/encode",
        headers={
            "Origin": "https://app.example",
            "Access-Control-Request-Method": "POST",
            "Access-Control-Request-Headers": "x-api-key, content-type",
        },
    )
    assert preflight.status_code == 200 and "x-api-key" in preflight.headers["access-control-allow-headers"].lower()


def test_a_body_without_a_key_is_refused_before_it_is_read(make_client):
    client = make_client(api_keys=KEYS, max_body_bytes=1024)
    r = client.post("/encode", content=b"x" * 10_000, headers={"Content-Type": "application/json"})
    assert r.status_code == 401  # not 413: nothing of it is read


def test_keys_compare_whole_and_exactly():
    assert accepted("abc", ["xyz", "abc"]) and not accepted("ab", ["abc"]) and not accepted("abcd", ["abc"])
    assert not accepted(None, ["abc"]) and not accepted("", [""])
    assert key_of({b"authorization": b"Bearer t"}) == "t" and key_of({b"x-api-key": b" t "}) == "t"
    assert key_of({}) is None


def test_keys_come_from_the_environment(monkeypatch):
    from curve_vae.service.settings import Settings

    monkeypatch.setenv("CURVE_VAE_API_KEYS", "a1, b2")
    monkeypatch.setenv("CURVE_VAE_METRICS", "false")
    s = Settings()
    assert s.api_keys == ["a1", "b2"] and s.metrics is False and "a1" not in repr(s)


def test_an_unexpected_failure_tells_nothing_of_the_inside(model_dir, runtime, monkeypatch):
    from fastapi.testclient import TestClient

    from curve_vae.service.app import create_app
    from curve_vae.service.settings import Settings

    def broken(*args, **kwargs):
        raise RuntimeError("failed in /srv/secret/models/decoder.onnx")

    monkeypatch.setattr(runtime, "reconstruct", broken)
    with TestClient(create_app(Settings(model_dir=model_dir), runtime=runtime), raise_server_exceptions=False) as c:
        r = c.post("/reconstruct", json={"curves": [CURVE]})
    assert r.status_code == 500
    assert "secret" not in r.text and "Traceback" not in r.text and "decoder.onnx" not in r.text
