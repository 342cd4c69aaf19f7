"""Fixtures of the service tests: real exported ONNX models, loaded runtimes, apps and a live server.

The test model is untrained and small (Table 1's cnn1), committed under tests/fixtures/ by
tests/fixtures/make_models.py, so these tests run in an install without torch; tests that need a
model that actually reconstructs use `shipped_runtime` (models/).
"""

from __future__ import annotations

import json
import os
import shutil
import socket
import subprocess
import sys
import time
from collections.abc import Callable, Iterator
from pathlib import Path

import httpx
import numpy as np
import pytest
from fastapi.testclient import TestClient

from curve_vae.geometry import random_control_points, sample_bspline
from curve_vae.service.app import create_app
from curve_vae.service.runtime import CurveRuntime
from curve_vae.service.settings import Settings

ROOT = Path(__file__).resolve().parents[2]
SHIPPED = ROOT / "models"
FIXTURES = ROOT / "tests" / "fixtures"


@pytest.fixture(scope="session")
def model_dir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """An untrained VAE (cnn1) with the shipped model's B-spline head and a learned prior, exported as
    training/export.py ships one: committed (tests/fixtures/make_models.py), so these tests need no torch."""
    return _copy(FIXTURES / "untrained-spline31", tmp_path_factory.mktemp("model"))


@pytest.fixture(scope="session")
def raw_model_dir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The same untrained VAE without a B-spline head: its decoder returns the raw points."""
    return _copy(FIXTURES / "untrained-raw", tmp_path_factory.mktemp("raw_model"))


@pytest.fixture(scope="session")
def params_model_dir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The same untrained VAE whose B-spline head places each point at a parameter of its own (uneven, as its
    random weights give them), like the shipped model's head."""
    return _copy(FIXTURES / "untrained-params31", tmp_path_factory.mktemp("params_model"))


@pytest.fixture(scope="session")
def closest_model_dir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The untrained B-spline VAE placed "closest" (its manifest's spline.placement, as `curve-vae export` writes
    it by default): the service places the input's points at their closest points on the reconstruction."""
    out = _copy(FIXTURES / "untrained-spline31", tmp_path_factory.mktemp("closest_model"))
    manifest = json.loads((out / "manifest.json").read_text())
    manifest["spline"]["placement"] = "closest"
    (out / "manifest.json").write_text(json.dumps(manifest, indent=2))
    return out


def _copy(src: Path, out: Path) -> Path:
    """A copy a test may change without changing the committed files."""
    shutil.copytree(src, out, dirs_exist_ok=True)
    return out


@pytest.fixture(scope="session")
def runtime(model_dir: Path) -> CurveRuntime:
    return CurveRuntime.load(model_dir, providers="cpu", intra_op_threads=1)


@pytest.fixture(scope="session")
def raw_runtime(raw_model_dir: Path) -> CurveRuntime:
    return CurveRuntime.load(raw_model_dir, providers="cpu", intra_op_threads=1)


@pytest.fixture(scope="session")
def params_runtime(params_model_dir: Path) -> CurveRuntime:
    return CurveRuntime.load(params_model_dir, providers="cpu", intra_op_threads=1)


@pytest.fixture(scope="session")
def closest_runtime(closest_model_dir: Path) -> CurveRuntime:
    return CurveRuntime.load(closest_model_dir, providers="cpu", intra_op_threads=1)


@pytest.fixture(scope="session")
def shipped_runtime() -> CurveRuntime:
    if not (SHIPPED / "manifest.json").is_file():
        pytest.skip("no shipped model: models/manifest.json is absent")
    return CurveRuntime.load(SHIPPED, providers="cpu", intra_op_threads=1)


@pytest.fixture
def make_client(model_dir: Path, runtime: CurveRuntime) -> Iterator[Callable[..., TestClient]]:
    """make_client(**settings) -> a started TestClient; the app shares the session's runtime."""
    clients: list[TestClient] = []

    def make(*, share_runtime: bool = True, **overrides: object) -> TestClient:
        settings = Settings(**{"model_dir": model_dir, **overrides})
        client = TestClient(create_app(settings, runtime=runtime if share_runtime else None))
        client.__enter__()
        clients.append(client)
        return client

    yield make
    for client in clients:
        client.__exit__(None, None, None)


@pytest.fixture
def client(make_client: Callable[..., TestClient]) -> TestClient:
    return make_client()


def bspline_curves(count: int, n_points: int = 161, *, seed: int = 0) -> np.ndarray:
    """(count, n_points, 2) curves of the paper's kind, in the 128×128 plane."""
    return sample_bspline(random_control_points(np.random.default_rng(seed), count), n_points)


@pytest.fixture
def curves() -> Callable[..., np.ndarray]:
    return bspline_curves


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class LiveServer:
    """`python -m curve_vae.service.cli` (what `curve-vae serve` runs) in a subprocess on a free loopback port."""

    def __init__(self, *args: str, env: dict[str, str] | None = None) -> None:
        self.port = free_port()
        self.url = f"http://127.0.0.1:{self.port}"
        cmd = [sys.executable, "-m", "curve_vae.service.cli", "--port", str(self.port), "--log-level", "warning", *args]
        self.proc = subprocess.Popen(
            cmd,
            cwd=ROOT,
            env={**os.environ, **(env or {})},
            stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT,
            text=True,
        )

    def wait_ready(self, timeout: float = 30.0) -> None:
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            if self.proc.poll() is not None:
                raise RuntimeError(f"server exited with {self.proc.returncode}:\n{self.proc.stdout.read()}")  # type: ignore[union-attr]
            try:
                if httpx.get(f"{self.url}/ready", timeout=1.0).status_code == 200:
                    return
            except httpx.TransportError:
                pass
            time.sleep(0.1)
        raise TimeoutError(f"{self.url} not ready after {timeout} s")

    def stop(self) -> int:
        if self.proc.poll() is None:
            self.proc.terminate()
            try:
                self.proc.wait(timeout=10)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait()
        self.proc.stdout.close()  # type: ignore[union-attr]
        return self.proc.returncode


@pytest.fixture
def server_factory() -> Iterator[Callable[..., LiveServer]]:
    """server_factory(*cli_args) -> a LiveServer, stopped at the end of the test."""
    servers: list[LiveServer] = []

    def start(*args: str, env: dict[str, str] | None = None) -> LiveServer:
        servers.append(LiveServer(*args, env=env))
        return servers[-1]

    yield start
    for server in servers:
        server.stop()


@pytest.fixture(scope="module")
def shipped_server() -> Iterator[LiveServer]:
    """`curve-vae serve` on the shipped model, for tests of what users see (the page, the README's answers)."""
    if not (SHIPPED / "manifest.json").is_file():
        pytest.skip("no shipped model: models/manifest.json is absent")
    server = LiveServer("--model-dir", str(SHIPPED), "--providers", "cpu")
    try:
        server.wait_ready()
        yield server
    finally:
        server.stop()


@pytest.fixture(scope="session")
def live_server(model_dir: Path) -> Iterator[LiveServer]:
    server = LiveServer("--model-dir", str(model_dir), "--providers", "cpu", "--max-body-bytes", "200000")
    try:
        server.wait_ready()
        yield server
    finally:
        server.stop()
