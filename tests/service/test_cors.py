"""Calls from pages on other origins (service.middleware): CORS headers for the origins the settings allow, and a 403
that says how to allow any other origin's preflight."""

from __future__ import annotations

CURVE = [[0, 0], [1, 2], [2.5, 3.2], [4, 3.5], [5.5, 3], [7, 1.5], [8, 0]]


def test_cors_off_by_default_and_a_preflight_is_told_how_to_allow_its_origin(client):
    r = client.options("/encode", headers={"Origin": "https://app.example", "Access-Control-Request-Method": "POST"})
    assert r.status_code == 403 and "access-control-allow-origin" not in r.headers
    assert r.json()["detail"] == (
        "origin: calls from https://app.example are not allowed (the server allows no other origin): start it with "
        "--cors-origins https://app.example or CURVE_VAE_CORS_ORIGINS=https://app.example"
    )
    assert client.options("/encode").status_code == 405  # not a preflight: the routes' own answer


def test_cors_allows_configured_origins(make_client):
    client = make_client(cors_origins="https://app.example, https://other.example")
    pre = {"Access-Control-Request-Method": "POST", "Access-Control-Request-Headers": "content-type"}
    r = client.options("/encode", headers={"Origin": "https://app.example", **pre})
    assert r.status_code == 200 and r.headers["access-control-allow-origin"] == "https://app.example"
    r = client.post("/encode", json={"curves": [CURVE]}, headers={"Origin": "https://other.example"})
    assert r.headers["access-control-allow-origin"] == "https://other.example"
    r = client.options("/encode", headers={"Origin": "https://evil.example", **pre})
    assert r.status_code == 403 and "access-control-allow-origin" not in r.headers
    assert "CURVE_VAE_CORS_ORIGINS=https://app.example,https://other.example,https://evil.example" in r.json()["detail"]


PREFLIGHT = {"Access-Control-Request-Method": "POST", "Access-Control-Request-Headers": "content-type, x-api-key"}


def test_a_page_on_an_allowed_origin_can_read_the_headers_it_needs(make_client):
    """The .npy seed and the mesh counts are exposed to scripts on the allowed origin; a preflight is cached 10 min
    and allows the API-key headers."""
    client = make_client(cors_origins=["https://app.example"])
    pre = client.options("/augment", headers={"Origin": "https://app.example", **PREFLIGHT})
    assert pre.status_code == 200 and pre.headers["access-control-max-age"] == "600"
    assert {"content-type", "x-api-key"} <= {
        h.strip().lower() for h in pre.headers["access-control-allow-headers"].split(",")
    }
    body = {"curve": [[0, 0], [3, 0], [4, 1], [3, 3], [0, 4]], "segments": 8}
    r = client.post("/revolve", json=body, headers={"Origin": "https://app.example"})
    exposed = {h.strip().lower() for h in r.headers["access-control-expose-headers"].split(",")}
    assert {"x-mesh-vertices", "x-mesh-faces", "x-mesh-closed", "x-augment-seed", "content-disposition"} <= exposed


def test_a_wildcard_allows_every_origin(make_client):
    client = make_client(cors_origins="*")
    r = client.options("/encode", headers={"Origin": "https://anyone.example", **PREFLIGHT})
    assert r.status_code == 200 and r.headers["access-control-allow-origin"] in ("*", "https://anyone.example")


def test_a_refused_preflight_lists_the_origins_already_allowed(make_client):
    client = make_client(cors_origins=["https://a.example"])
    r = client.options("/v2/models/encoder/infer", headers={"Origin": "https://b.example", **PREFLIGHT})
    assert r.status_code == 403
    message = (
        "calls from https://b.example are not allowed (the server allows https://a.example): start it with "
        "--cors-origins https://a.example,https://b.example or "
        "CURVE_VAE_CORS_ORIGINS=https://a.example,https://b.example"
    )
    assert r.json() == {"error": f"origin: {message}"}  # under /v2 in the protocol's error format


def test_a_plain_options_or_a_same_origin_request_is_not_a_preflight(client):
    assert client.options("/encode", headers={"Origin": "https://app.example"}).status_code == 405
    assert client.get("/health", headers={"Origin": "https://app.example"}).status_code == 200
