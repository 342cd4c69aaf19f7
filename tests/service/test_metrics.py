"""Prometheus metrics (service.metrics): each request counted by its route template and status, 404s and 413s
included, timed, per app; unknown paths share one label."""

from __future__ import annotations

import pytest
from fastapi.testclient import TestClient

from curve_vae.service.app import create_app
from curve_vae.service.settings import Settings


def test_metrics(client, curves):
    client.post("/encode", json={"curves": curves(3).tolist()})
    client.post("/encode", json={"curves": [[[0, 0]]]})
    client.get("/nowhere")
    text = client.get("/metrics").text
    assert 'curve_vae_http_requests_total{method="POST",route="/encode",status="200"} 1.0' in text
    assert 'curve_vae_http_requests_total{method="POST",route="/encode",status="422"} 1.0' in text
    assert 'curve_vae_http_requests_total{method="GET",route="unmatched",status="404"} 1.0' in text
    assert 'curve_vae_batch_size_bucket{le="4.0",route="/encode"} 1.0' in text
    assert 'curve_vae_http_request_duration_seconds_count{method="POST",route="/encode"} 2.0' in text
    assert "curve_vae_inference_duration_seconds_count" in text and "curve_vae_ready 1.0" in text


def test_metrics_are_per_app(make_client):
    a, b = make_client(), make_client()
    a.get("/health")
    assert 'route="/health"' not in b.get("/metrics").text


def _count(text: str, method: str, route: str, status: str) -> float:
    key = f'curve_vae_http_requests_total{{method="{method}",route="{route}",status="{status}"}} '
    lines = [line for line in text.splitlines() if line.startswith(key)]
    return float(lines[0][len(key) :]) if lines else 0.0


@pytest.mark.parametrize(
    ("method", "path", "kwargs", "route", "status"),
    [
        pytest.param("get", "/v2/models/resnet", {}, "/v2/models/{name}", "404", id="path-parameter-template"),
        pytest.param("get", "/v2/models/encoder", {}, "/v2/models/encoder", "200", id="fixed-route"),
        pytest.param("get", "/wp-login.php", {}, "unmatched", "404", id="scanner"),
        pytest.param("post", "/reconstruct", {"content": b" " * 5000}, "/reconstruct", "413", id="413-before-routing"),
        pytest.param("post", "/nowhere", {"content": b" " * 5000}, "unmatched", "413", id="413-unknown-path"),
        pytest.param("post", "/health", {}, "/health", "405", id="wrong-method"),
    ],
)
def test_requests_are_counted_by_route_template_and_status(make_client, method, path, kwargs, route, status):
    client = make_client(max_body_bytes=4096)
    getattr(client, method)(path, **kwargs)
    text = client.get("/metrics").text
    assert _count(text, method.upper(), route, status) == 1.0
    assert f'route="{path}"' not in text or route == path  # never the raw path of a parametrised route


def test_a_failure_inside_the_app_is_counted_as_500(model_dir, runtime, monkeypatch):
    def broken(*args, **kwargs):
        raise RuntimeError("broken")

    monkeypatch.setattr(runtime, "encode", broken)
    with TestClient(create_app(Settings(model_dir=model_dir), runtime=runtime), raise_server_exceptions=False) as c:
        c.post("/encode", json={"curves": [[[0, 0], [1, 2], [2, 3], [3, 1]]]})
        text = c.get("/metrics").text
    assert _count(text, "POST", "/encode", "500") == 1.0


def test_the_batch_size_histogram_counts_curves_per_request(client, curves):
    for n in (1, 3, 3, 20):
        assert client.post("/encode", json={"curves": curves(n).tolist()}).status_code == 200
    text = client.get("/metrics").text
    buckets = {le: 0 for le in ("1.0", "2.0", "4.0", "8.0", "16.0", "32.0")}
    for le in buckets:  # cumulative: the requests of at most `le` curves
        buckets[le] = sum(1 for n in (1, 3, 3, 20) if n <= float(le))
        assert f'curve_vae_batch_size_bucket{{le="{le}",route="/encode"}} {buckets[le]:.1f}' in text
    assert 'curve_vae_batch_size_sum{route="/encode"} 27.0' in text
