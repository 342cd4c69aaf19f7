"""The page at / and the interactive API docs (service.web), served from the package so that they work offline: the
page and its static files byte for byte, and /docs and /redoc loading their scripts from the server, not a CDN."""

from __future__ import annotations

import re
from pathlib import Path

import fastapi_offline
import pytest

import curve_vae.service

STATIC = Path(curve_vae.service.__file__).resolve().parent / "static"
ASSETS = Path(fastapi_offline.__file__).resolve().parent / "static"


def test_the_page_is_the_packaged_index_html(client):
    r = client.get("/")
    assert r.status_code == 200 and r.headers["content-type"].startswith("text/html")
    assert r.content == (STATIC / "index.html").read_bytes()


@pytest.mark.parametrize("name", sorted(p.name for p in STATIC.iterdir() if p.is_file()))
def test_every_static_file_is_served_as_it_is(client, name):
    r = client.get(f"/static/{name}")
    assert r.status_code == 200 and r.content == (STATIC / name).read_bytes()


def test_the_page_refers_only_to_files_the_server_has(client):
    html = client.get("/").text
    refs = re.findall(r'(?:src|href)="([^"#]+)"', html)
    local = [ref for ref in refs if not ref.startswith(("http:", "https:", "mailto:", "data:"))]
    assert local, "the page loads no script or style"
    assert not [ref for ref in refs if ref.startswith(("http:", "https:")) and ref.endswith((".js", ".css"))]
    for ref in local:
        assert client.get(ref if ref.startswith("/") else f"/{ref}").status_code == 200, ref


@pytest.mark.parametrize(
    ("path", "scripts"),
    [
        pytest.param("/docs", ["swagger-ui-bundle.js", "swagger-ui.css", "favicon.png"], id="swagger-ui"),
        pytest.param("/redoc", ["redoc.standalone.js", "favicon.png"], id="redoc"),
    ],
)
def test_the_docs_load_their_assets_from_this_server(client, path, scripts):
    html = client.get(path).text
    assert "/openapi.json" in html and "curve-vae" in html
    assert not re.search(r"(src|href)=[\"']https?://", html), "an asset from the internet"
    assert "fonts.googleapis" not in html
    for name in scripts:
        assert f"/docs-assets/{name}" in html
        r = client.get(f"/docs-assets/{name}")
        assert r.status_code == 200 and r.content == (ASSETS / name).read_bytes()


def test_the_page_and_docs_stay_out_of_the_api_schema(client):
    paths = client.get("/openapi.json").json()["paths"]
    assert not {"/", "/docs", "/redoc"} & set(paths)
    assert not [p for p in paths if p.startswith(("/static", "/docs-assets"))]
