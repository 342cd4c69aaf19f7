"""The app factory and its lifespan (service.app): nothing served before the model is loaded, a model that cannot load
fails the start loudly, and default settings serve the shipped model."""

from __future__ import annotations

import numpy as np
import pytest
from fastapi.testclient import TestClient

from curve_vae.inference.model.manifest import ModelLoadError
from curve_vae.service.app import create_app
from curve_vae.service.settings import Settings

CURVE = [[0, 0], [1, 2], [2.5, 3.2], [4, 3.5], [5.5, 3], [7, 1.5], [8, 0]]


def test_not_ready_before_the_model_is_loaded(model_dir):
    client = TestClient(create_app(Settings(model_dir=model_dir)))  # lifespan not run: nothing loaded
    assert client.get("/health").status_code == 200
    r = client.get("/ready")
    assert r.status_code == 503 and "not loaded" in r.json()["detail"]
    assert client.post("/encode", json={"curves": [CURVE]}).status_code == 503
    assert client.get("/model").status_code == 503


def test_the_lifespan_loads_the_model_and_fails_loudly(make_client, tmp_path):
    client = make_client(share_runtime=False, providers="cpu")  # waits for the warm-up: tests/helpers.wait_ready
    assert client.get("/ready").status_code == 200
    with pytest.raises(ModelLoadError, match="manifest.json is missing"):
        with TestClient(create_app(Settings(model_dir=tmp_path))):
            pass


def test_the_shipped_model_is_served_by_default(shipped_runtime, curves):
    """Default settings serve models/; its checksums pass and it keeps the frame behaviour of item 3."""
    from curve_vae.inference.model.shipped import SHIPPED

    with TestClient(create_app(Settings(providers="cpu"))) as client:
        info = client.get("/model").json()
        assert info["name"] == shipped_runtime.manifest.name and info["version"] == shipped_runtime.manifest.version
        assert Settings().model_dir == SHIPPED
        c = curves(2, 75, seed=4)
        base = client.post("/reconstruct", json={"curves": c.tolist()}).json()
        moved = client.post("/reconstruct", json={"curves": (c * 0.01 - 7).tolist()}).json()
        np.testing.assert_allclose(
            np.array(moved["curves"]), np.array(base["curves"]) * 0.01 - 7, atol=1e-6 * 128 * 0.01
        )


def test_a_warm_up_that_fails_is_stated_by_health_and_ready(model_dir, monkeypatch):
    """The server answers while the model warms up; where the warm-up fails, /health and /ready answer 503 saying
    why (an orchestrator restarts the process) and model requests are refused, not left waiting."""
    from curve_vae.inference.runtime import CurveRuntime

    def broken(self, *, graphs: bool = True) -> None:
        raise ModelLoadError("warm-up request failed: the reading broke")

    monkeypatch.setattr(CurveRuntime, "warm_up", broken)
    with TestClient(create_app(Settings(model_dir=model_dir, providers="cpu"))) as client:
        r = client.post("/encode", json={"curves": [CURVE]})  # waits for the warm-up, then is refused
        assert r.status_code == 503 and "the reading broke" in r.json()["detail"]
        for path in ("/health", "/ready"):
            r = client.get(path)
            assert r.status_code == 503 and r.json()["status"] == "failed" and "the reading broke" in r.json()["detail"]
