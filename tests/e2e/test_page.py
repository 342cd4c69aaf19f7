"""The page at / in a real headless browser (Debian's chromium-headless-shell, driven by Playwright: tests/e2e/
browser.py) against uvicorn on loopback.

Every test fails on a JavaScript error or a console error. A screenshot of the page lands in test-artifacts/.
"""

from __future__ import annotations

import json
import os
import re
from collections.abc import Iterator
from pathlib import Path

import httpx
import numpy as np
import pytest

from curve_vae.service.live import LiveServer
from tests.e2e.browser import ARGS, CHROMIUM
from tests.helpers import ROOT, SHIPPED, shipped_live_server

ARTIFACTS = ROOT / "test-artifacts"
H = 700  # the board's height: API coordinates are the board's with y up

if CHROMIUM is None:
    if os.environ.get("CI"):
        raise RuntimeError("no browser: .ci/run installs one with apt-get install chromium-headless-shell")
    pytest.skip("no browser is installed (apt-get install chromium-headless-shell)", allow_module_level=True)

from playwright.sync_api import Browser, Page, sync_playwright  # noqa: E402

from tests.e2e.drawing import arc, draw  # noqa: E402,F401 - the page tests import them from here too

pytestmark = pytest.mark.integration


@pytest.fixture(scope="module")
def server() -> Iterator[LiveServer]:
    """The shipped model, so that the page draws real reconstructions and interpolants; one worker, because these
    tests watch the encoding cache answer a slider's moves, and each worker keeps its own (the browser's requests
    may reach either of two: docs/DEPLOYMENT.md)."""
    yield from shipped_live_server("--workers", "1")


@pytest.fixture(scope="module")
def browser() -> Iterator[Browser]:
    with sync_playwright() as p:
        b = p.chromium.launch(executable_path=CHROMIUM, args=ARGS)
        yield b
        b.close()


def open_page(browser: Browser, url: str, *, width: int = 1280, height: int = 900) -> tuple[Page, list[str]]:
    page = browser.new_context(viewport={"width": width, "height": height}, accept_downloads=True).new_page()
    errors: list[str] = []
    page.on("console", lambda m: errors.append(f"console: {m.text}") if m.type == "error" else None)
    page.on("pageerror", lambda e: errors.append(f"page error: {e}"))
    page.goto(url)
    return page, errors


def drawn(page: Page, selector: str) -> np.ndarray:
    """Points of an SVG path of the board, back in API coordinates."""
    d = page.locator(selector).get_attribute("d")
    assert d
    pts = np.array([[float(v) for v in seg[1:].split(",")] for seg in d.split()])
    return np.stack([pts[:, 0], H - pts[:, 1]], axis=1)


def state(page: Page) -> dict:
    return page.evaluate("JSON.parse(JSON.stringify(window.curveVae))")


def test_draw_interpolate_triplet_download_vase(browser, server, tmp_path):
    page, errors = open_page(browser, server.url + "/")
    _check_pair(page, server.url)
    s = _check_triplet(page, server.url)
    _check_downloads(page, s, server.url)
    _check_vase(page)
    ARTIFACTS.mkdir(exist_ok=True)
    page.screenshot(path=str(ARTIFACTS / "page.png"), full_page=True)
    assert errors == []


def _graph_rows(url: str) -> dict[str, float]:
    """Rows each graph has run on the server (GET /metrics: curve_vae_graph_rows)."""
    text = httpx.get(url + "/metrics", timeout=10).text
    return {g: float(re.search(rf'curve_vae_graph_rows{{graph="{g}"}} (\S+)', text)[1]) for g in ("encoder", "decoder")}


def _check_pair(page: Page, url: str) -> None:
    """Two drawn curves: their reconstructions, the mix at the slider's weight and the strip are the API's answers."""
    draw(page, arc(500, 420, 250, np.pi, 2 * np.pi))  # a bowl, drawn left to right
    draw(page, arc(500, 250, 220, 0.9 * np.pi, 0.1 * np.pi))  # a hump
    page.wait_for_function("window.curveVae.result !== null && window.curveVae.strip.length === 5")
    page.wait_for_function("document.querySelectorAll('path.reconstruction').length === 2")

    posted: list[str] = []
    page.on("request", lambda r: posted.append(r.url.rsplit("/", 1)[-1]) if r.method == "POST" else None)
    before = _graph_rows(url)
    page.locator("#weight").fill("0.25")  # the slider
    page.wait_for_function("window.curveVae.result && window.curveVae.result.weights[1] === 0.25")
    after = _graph_rows(url)
    # a move: one request, and the server reads its curves from the encoding cache: no encoding, one decoded row
    assert posted == ["interpolate"], posted
    assert after["encoder"] == before["encoder"] and after["decoder"] - before["decoder"] == 1, (before, after)
    s = state(page)
    answer = httpx.post(url + "/interpolate", json=s["result"]["body"], timeout=30).json()
    np.testing.assert_allclose(drawn(page, "#interpolant"), answer["curves"][0], atol=2e-3)  # drawn = API's answer
    strip_body = {**s["result"]["body"], "steps": 5, "n_points": 60, "output": "points", "metrics": False}
    del strip_body["weights"]
    strip = httpx.post(url + "/interpolate", json=strip_body, timeout=30).json()
    np.testing.assert_allclose(s["strip"], strip["curves"], atol=1e-9)
    smooth = page.locator("dd[data-metric='mix smoothness']").inner_text()
    assert re.fullmatch(r"\d+\.\d\d° a point on average, \d+\.\d° at the sharpest", smooth), smooth
    # each curve's row in the list says how close the model read it, relative to its size: the API's closeness
    again = httpx.post(url + "/reconstruct", json={"curves": s["curves"], "refine": s["recon"][0]["refine"]}).json()
    for i, name in enumerate("AB"):
        near = again["closeness"][i]
        shown = page.locator(f"#curve-list li[data-name='{name}'] .closeness").inner_text()
        want = f"{100 * near['rms']:.2f}% off, {100 * near['max']:.2f}% at most"
        assert shown.startswith(want), shown

    page.check("#show-ctrl")
    assert page.locator(".control-polygon").count() == 3  # two reconstructions and the mix
    assert len(s["result"]["spline"]["control_points"]) == 31
    shape = page.locator("dd[data-metric='mix shape']").inner_text()
    assert shape == "no self-crossing; 31 control points"


def _check_triplet(page: Page, url: str) -> dict:
    """A third curve in triplet mode: the strip as a triangle, and a click on the triangle mixes near B; the state."""
    page.check("#mode-triplet")
    draw(page, arc(500, 350, 150, 0.5 * np.pi, 2.3 * np.pi))  # a third curve
    page.wait_for_function("window.curveVae.curves.length === 3 && window.curveVae.strip.length === 10")
    page.wait_for_function("document.querySelectorAll('#strip svg').length === 10")
    rows = page.locator("#strip .strip-row")
    assert [rows.nth(i).locator("svg").count() for i in range(rows.count())] == [1, 2, 3, 4]  # the grid as a triangle
    box = page.locator("#triangle").bounding_box()
    assert box is not None
    page.mouse.click(box["x"] + 30 / 220 * box["width"], box["y"] + 170 / 200 * box["height"])  # near B's corner
    page.wait_for_function("window.curveVae.result && window.curveVae.result.weights.length === 3")
    page.wait_for_function("window.curveVae.result.weights[1] > 0.6")
    s = state(page)
    answer = httpx.post(url + "/interpolate", json=s["result"]["body"], timeout=30).json()
    np.testing.assert_allclose(drawn(page, "#interpolant"), answer["curves"][0], atol=2e-3)
    return s


def _check_downloads(page: Page, s: dict, url: str) -> None:
    """The JSON, CSV and SVG downloads hold the three curves, their reconstructions, the mix and the in-betweens, each
    named with its role; the curl command is the request's."""
    with page.expect_download() as download:
        page.click("#download-json")
    saved = {c["name"]: c for c in json.loads(Path(download.value.path()).read_text())["curves"]}
    roles = [c["role"] for c in saved.values()]
    assert [n for n, c in saved.items() if c["role"] == "input"] == ["A", "B", "C"]
    assert roles.count("reconstruction") == 3 and roles.count("interpolant") == 1 + 10  # the mix, the grid
    np.testing.assert_allclose(saved["mix"]["points"], s["result"]["points"])
    assert saved["A reconstructed"]["of"] == "A" and saved["1 A"]["weights"] == {"A": 1, "B": 0, "C": 0}
    with page.expect_download() as download:
        page.click("#download-csv")
    rows = Path(download.value.path()).read_text().splitlines()
    assert rows[0].startswith("curve,role,") and len(rows) == 1 + sum(len(c["points"]) for c in saved.values())
    with page.expect_download() as download:
        page.click("#download-svg")
    assert "<path" in Path(download.value.path()).read_text()

    page.click("#curl-box summary")  # the curl command on demand
    page.click("#copy-curl")
    curl = page.locator("#curl").inner_text()
    assert curl.startswith(f"curl -s {url}/interpolate")


def _check_vase(page: Page) -> None:
    """The vase of the mix: its mesh, and an STL download of as many triangles as its header says."""
    page.click("#vase")
    page.wait_for_function("window.curveVae.vase && window.curveVae.vase.faces.length > 0")
    s = state(page)
    assert len(s["vase"]["faces"]) == s["vase"]["faces_header"]
    with page.expect_download() as download:
        page.click("#download-stl")
    stl = Path(download.value.path()).read_bytes()
    assert len(stl) == 84 + 50 * int.from_bytes(stl[80:84], "little") > 84


def test_errors_appear_next_to_their_cause(browser, server_factory, model_dir):
    api = server_factory("--model-dir", str(model_dir), "--providers", "cpu", "--max-curves", "1")
    api.wait_ready()
    page, errors = open_page(browser, api.url + "/")
    draw(page, [(100, 100), (106, 100), (112, 100)])  # a dab of three points, not a stroke (one or two: a click)
    assert "Too short" in page.locator("#board-error").inner_text()
    page.click("#sample")  # two curves, but this server takes one per request
    page.wait_for_function("document.getElementById('board-error').textContent.includes('at most 1')")
    assert page.locator("#board-error").inner_text() == "/sample: count: at most 1, got 2"
    assert [e for e in errors if "422" not in e] == []  # the browser logs the failed request itself; nothing else


def test_page_on_another_origin_with_cors(browser, server, server_factory, model_dir):
    api = server_factory("--model-dir", str(model_dir), "--providers", "cpu", "--cors-origins", server.url)
    api.wait_ready()
    page, errors = open_page(browser, f"{server.url}/?api={api.url}")
    page.click("#sample")
    page.wait_for_function("window.curveVae.result !== null")
    metrics = httpx.get(api.url + "/metrics").text  # the other origin answered
    assert 'curve_vae_http_requests_total{method="POST",route="/sample",status="200"} 1.0' in metrics
    assert errors == []


def test_fit_closely_refines_the_reconstructions_and_the_mix(browser, server):
    page, errors = open_page(browser, server.url + "/")
    t = np.linspace(0, 1, 40)
    draw(page, list(zip(200 + 600 * t, 350 + 120 * np.sin(2 * np.pi * t) * (1 - 0.5 * t))))  # an S-stroke
    draw(page, arc(500, 420, 250, np.pi, 2 * np.pi))  # a bowl
    page.wait_for_function("window.curveVae.result !== null && window.curveVae.recon.length === 2")
    plain = state(page)
    assert plain["recon"][0]["refine"] == 0 and plain["result"]["body"]["refine"] == 0
    page.check("#fit-closely")
    page.wait_for_function(
        "window.curveVae.recon[0].refine === 10 && window.curveVae.result && window.curveVae.result.body.refine === 10"
    )
    fitted = state(page)
    # the default already looks again (about 2× closer than the reading alone); ten fitting steps come closer still
    assert fitted["recon"][0]["mse"] < 0.7 * plain["recon"][0]["mse"], (plain["recon"][0], fitted["recon"][0])
    body = {"curves": fitted["curves"], "spacing": "auto", "n_points": 100, "output": "both", "refine": 10}
    answer = httpx.post(server.url + "/reconstruct", json=body, timeout=30).json()
    np.testing.assert_allclose(drawn(page, "path.reconstruction >> nth=0"), answer["curves"][0], atol=2e-3)
    mix = httpx.post(server.url + "/interpolate", json=fitted["result"]["body"], timeout=30).json()
    np.testing.assert_allclose(drawn(page, "#interpolant"), mix["curves"][0], atol=2e-3)
    assert errors == []


def test_phone_sized_screen(browser, server):
    page, errors = open_page(browser, server.url + "/", width=390, height=844)
    assert page.evaluate("document.documentElement.scrollWidth") <= 390  # no sideways scrolling
    assert page.locator("#board").bounding_box()["width"] <= 390  # type: ignore[index]
    page.click("#sample")
    page.wait_for_function("window.curveVae.result !== null")
    assert errors == []


@pytest.mark.parametrize(("path", "text"), [("/docs", "curve-vae"), ("/redoc", "curve-vae")])
def test_api_docs_work_offline(browser, server, path, text):
    page = browser.new_context().new_page()
    outside: list[str] = []

    def only_loopback(route):
        if route.request.url.startswith(server.url):
            route.continue_()
        else:
            outside.append(route.request.url)
            route.abort()

    # ReDoc's footer tries its maker's logo from a CDN and drops it when that fails (an onError handler in
    # redoc.standalone.js): the reference is complete without it. Nothing else may leave the machine.
    redoc_logo = "https://cdn.redoc.ly/redoc/logo-mini.svg"

    page.route("**/*", only_loopback)
    page.goto(server.url + path)
    page.wait_for_selector(".swagger-ui .info .title" if path == "/docs" else "h1", timeout=20_000)
    assert text in page.content()
    assert [url for url in outside if url != redoc_logo] == []


def test_page_sends_the_api_key_the_user_types(browser, server_factory):
    api = server_factory("--model-dir", str(SHIPPED), "--providers", "cpu", env={"CURVE_VAE_API_KEYS": "s3cret-key"})
    api.wait_ready()
    page, errors = open_page(browser, api.url + "/")  # the page itself loads without a key
    page.click("#sample")
    page.wait_for_function("document.getElementById('board-error').textContent.includes('API key')")
    assert "type it in the API key field" in page.locator("#board-error").inner_text()
    page.fill("#api-key", "s3cret-key")
    page.click("#sample")
    page.wait_for_function("window.curveVae.result !== null")
    assert page.locator("#board-error").inner_text() == ""
    assert [e for e in errors if "401" not in e] == []  # the browser logs the refused request itself; nothing else


def test_samples_come_from_the_prior_the_user_picks(browser, server_factory, tmp_path):
    """A server with a folder of priors lists them in the page's menu; the pick goes into /sample's body."""
    from curve_vae.cli import main

    t = np.linspace(0, 1, 60)
    strokes = [np.stack([t * 6, a * np.sin(np.pi * t * k)], 1) for a, k in zip(np.linspace(0.5, 2, 12), [1, 2] * 6)]
    (tmp_path / "strokes.json").write_text(json.dumps([c.tolist() for c in strokes]))
    priors = tmp_path / "priors"
    fit = ["prior", "--curves", str(tmp_path / "strokes.json"), "-o", str(priors / "waves.npz"), "--refine", "0"]
    assert main([*fit, "--model-dir", str(SHIPPED)]) == 0
    api = server_factory("--model-dir", str(SHIPPED), "--providers", "cpu", "--priors-dir", str(priors))
    api.wait_ready()
    page, errors = open_page(browser, api.url + "/")
    page.wait_for_function("[...document.querySelectorAll('#prior option')].map((o) => o.value).includes('waves')")
    options = page.eval_on_selector_all("#prior option", "os => os.map((o) => o.value)")
    assert options == ["learned", "standard", "waves"]
    page.select_option("#prior", "waves")
    with page.expect_response("**/sample") as answer:
        page.click("#sample")
    assert json.loads(answer.value.request.post_data or "{}")["prior"] == "waves"
    assert answer.value.json()["prior"] == "waves" and len(answer.value.json()["curves"]) == 2
    page.wait_for_function("window.curveVae.result !== null")
    assert errors == []


TINY_PAGE = """<!doctype html><meta charset="utf-8"><title>another origin</title><link rel="icon" href="data:,">
<script>
window.reconstruct = async (api) => {
  const body = JSON.stringify({curves: [[[0, 0], [1, 2], [2.5, 3.2], [4, 3.5], [5.5, 3], [7, 1.5], [8, 0]]]});
  try {  // JSON is not a "simple" request: the browser sends a preflight first
    const r = await fetch(api + "/reconstruct", {method: "POST", headers: {"Content-Type": "application/json"}, body});
    return {status: r.status, body: await r.json()};
  } catch (e) { return {error: String(e)}; }
};
</script>"""


@pytest.fixture
def other_origin(tmp_path) -> Iterator[str]:
    """A tiny page served on a second loopback port: another origin than any server's."""
    import functools
    import http.server
    import threading

    (tmp_path / "index.html").write_text(TINY_PAGE)

    class Quiet(http.server.SimpleHTTPRequestHandler):
        def log_message(self, *args: object) -> None:
            pass

    handler = functools.partial(Quiet, directory=str(tmp_path))
    httpd = http.server.ThreadingHTTPServer(("127.0.0.1", 0), handler)
    thread = threading.Thread(target=httpd.serve_forever, daemon=True)
    thread.start()
    yield f"http://127.0.0.1:{httpd.server_address[1]}"
    httpd.shutdown()
    thread.join()


def test_a_page_on_another_origin_calls_a_server_that_allows_it(
    browser, server, server_factory, model_dir, other_origin
):
    """CURVE_VAE_CORS_ORIGINS lets the origin's fetch through its preflight; a server without it refuses the
    preflight with a 403 that says how to allow the origin, and the browser blocks the call."""
    api = server_factory(
        "--model-dir", str(model_dir), "--providers", "cpu", env={"CURVE_VAE_CORS_ORIGINS": other_origin}
    )
    api.wait_ready()
    page, errors = open_page(browser, other_origin + "/")
    answer = page.evaluate("(api) => window.reconstruct(api)", api.url)
    assert answer["status"] == 200 and np.shape(answer["body"]["curves"]) == (1, 7, 2), answer
    assert errors == []

    refused = page.evaluate("(api) => window.reconstruct(api)", server.url)  # the shipped server: no origins set
    assert "Failed to fetch" in refused["error"]
    assert any("CORS policy" in e for e in errors), errors
    preflight = httpx.options(
        server.url + "/reconstruct",
        headers={"Origin": other_origin, "Access-Control-Request-Method": "POST"},
        timeout=10,
    )
    assert preflight.status_code == 403
    assert f"--cors-origins {other_origin} or CURVE_VAE_CORS_ORIGINS={other_origin}" in preflight.json()["detail"]
