"""openapi.yaml (service.openapi) is the app's own schema and documents every status the service answers; the live
schema states the model's and the settings' bounds; and the service needs no torch."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import yaml

from curve_vae.service.openapi import ROOT_FILE, openapi_spec, render

ROOT = Path(__file__).resolve().parents[2]


def test_openapi_yaml_is_in_sync_with_the_app():
    assert ROOT_FILE.is_file(), "openapi.yaml is missing: run python -m curve_vae.service.openapi"
    assert ROOT_FILE.read_text() == render(), (
        "openapi.yaml drifted from the app: run python -m curve_vae.service.openapi"
    )


def test_every_status_is_documented_with_an_example():
    spec = yaml.safe_load(ROOT_FILE.read_text())
    paths = spec["paths"]
    for path in ("/encode", "/decode", "/reconstruct", "/interpolate", "/sample", "/augment"):
        op = paths[path]["post"]
        assert {"200", "413", "422", "503"} <= set(op["responses"]), path
        assert op["requestBody"]["content"]["application/json"]["examples"], path
        for code in ("413", "422", "503"):
            assert op["responses"][code]["content"]["application/json"]["example"]["detail"], (path, code)
        assert op["x-codeSamples"][0]["source"].startswith("curl "), path
    for path in ("/fit", "/revolve"):  # geometry only: no model, so no 503
        op = paths[path]["post"]
        assert {"200", "413", "422"} <= set(op["responses"]), path
        assert op["requestBody"]["content"]["application/json"]["examples"], path
        assert op["x-codeSamples"][0]["source"].startswith("curl "), path
    assert {"model/obj", "model/stl"} <= set(paths["/revolve"]["post"]["responses"]["200"]["content"])
    assert {"application/json", "application/octet-stream"} <= set(
        paths["/augment"]["post"]["responses"]["200"]["content"]
    )
    for path in ("/ready", "/model"):
        assert {"200", "503"} <= set(paths[path]["get"]["responses"]), path
    assert {"/health", "/metrics"} <= set(paths)


def test_the_service_runs_without_torch(model_dir):
    """Import, load and serve with torch made unimportable: the service never needs it."""
    code = f"""
import sys
sys.modules["torch"] = None  # any `import torch` now raises ImportError
from fastapi.testclient import TestClient
from curve_vae.service.app import create_app
from curve_vae.service.settings import Settings
import curve_vae.service.server, curve_vae.service.openapi
with TestClient(create_app(Settings(model_dir={str(model_dir)!r}, providers="cpu"))) as client:
    r = client.post("/reconstruct", json={{"curves": [[[0, 0], [1, 2], [2, 3], [3, 3], [4, 1]]]}})
    assert r.status_code == 200, r.text
assert sys.modules["torch"] is None
print("ok")
"""
    out = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, timeout=60)
    assert out.returncode == 0 and out.stdout.strip() == "ok", out.stderr


def test_importing_the_app_loads_no_torch():
    code = (
        "import sys, curve_vae.service.app, curve_vae.service.server, curve_vae.inference.runtime; "
        "assert 'torch' not in sys.modules; print('ok')"
    )
    out = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, timeout=60)
    assert out.returncode == 0 and out.stdout.strip() == "ok", out.stderr


def test_the_running_app_serves_the_same_schema_and_docs(client):
    live = client.get("/openapi.json").json()
    prior = live["components"]["schemas"]["SampleRequest"]["properties"]["prior"]["anyOf"][0]
    assert prior.pop("enum") == ["learned", "standard"]  # the live schema names the priors this server has
    assert live == openapi_spec()
    assert client.get("/docs").status_code == 200


def test_the_live_schema_states_the_model_and_the_settings_bounds(make_client, runtime):
    spec = make_client(max_curves=7, max_points=300, max_stream_curves=900).get("/openapi.json").json()["components"]
    latents = spec["schemas"]["DecodeRequest"]["properties"]["latents"]
    assert (
        latents["maxItems"] == 7 and latents["items"]["minItems"] == latents["items"]["maxItems"] == runtime.latent_dim
    )
    curves = spec["schemas"]["ReconstructRequest"]["properties"]["curves"]
    assert curves["maxItems"] == 7 and curves["items"]["maxItems"] == 300
    assert spec["schemas"]["SampleRequest"]["properties"]["count"]["maximum"] == 7
    assert spec["schemas"]["AugmentRequest"]["properties"]["count"]["maximum"] == 900
    assert spec["schemas"]["InterpolateRequest"]["not"] == {"required": ["steps", "weights"]}
