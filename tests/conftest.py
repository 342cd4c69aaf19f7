"""Fixtures of the inference and service tests: real exported ONNX models, loaded runtimes, apps and live servers.

The shared runtimes have no encoding cache (cache_bytes=0), so that a test's answer never depends on which test
read the same curve before it; the cache's own tests make runtimes with one.

The test model is untrained and small (Table 1's cnn1), committed under tests/fixtures/ by
tests/fixtures/make_models.py, so these tests run in an install without torch; tests that need a
model that actually reconstructs use `shipped_runtime` (models/).
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from collections.abc import Callable, Iterator
from pathlib import Path

import numpy as np
import pytest
from fastapi.testclient import TestClient
from threadpoolctl import threadpool_limits

from curve_vae.inference.model.opening import compiled_kernels
from curve_vae.inference.runtime import CurveRuntime
from curve_vae.service.app import create_app
from curve_vae.service.live import LiveServer
from curve_vae.service.settings import Settings
from tests.helpers import FIXTURES, SHIPPED, bspline_curves, shipped_live_server, spawn_server, wait_ready

# The suite starts many Python processes (xdist's workers, servers, the command line, training runs) that
# import the same modules: where the environment says PYTHONDONTWRITEBYTECODE (containers often do, these machines
# among them), each would compile the project's sources again, and each worker would rewrite every test module's
# asserts again (the collection alone 15.2 s -> 8.7 s a process with the caches). They are written to __pycache__/,
# which git ignores, as any Python run's; set here, before xdist starts its workers, so that they and every
# subprocess inherit it.
os.environ.pop("PYTHONDONTWRITEBYTECODE", None)
sys.dont_write_bytecode = False
# Two workers share the cores, and torch's OpenMP threads spin between parallel regions by default, on CPU the other
# worker is waiting for: here they sleep instead (a tiny training run beside a busy core: 11 user CPU-s against
# 16-20; the training and export tests, tests/training/test_end_to_end.py, tests/training/test_export.py and
# tests/curve_vae/commands/test_train.py on two workers: 179 CPU-s and 109 s against 230 and 134). What the tests
# check does not depend on how an idle thread waits; the command line's and the servers' processes inherit it.
os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")
# numpy's OpenBLAS threads likewise spin 2^28 cycles after each call before they sleep; 2^4 here (the data, mixes,
# fitting and suite tests on two workers: 68-73 CPU-s and 37-41 s against 77 and 43, over five runs and two).
os.environ.setdefault("OPENBLAS_THREAD_TIMEOUT", "4")

#: Fixtures that start a server in a subprocess: a test that uses one is marked "integration".
SERVER_FIXTURES = {"server_factory", "shipped_server", "live_server"}


@pytest.fixture(autouse=True)
def blas_threads_restored() -> Iterator[None]:
    """A started app caps numpy's BLAS threads process-wide (inference/model/cpus.py); each test gets back what it
    had."""
    with threadpool_limits(limits=None, user_api="blas"):
        yield


#: The background compile of the reading's kernels a fresh checkout starts (pytest_configure), stopped at the end.
_KERNELS = pytest.StashKey[subprocess.Popen]()


def pytest_configure(config: pytest.Config) -> None:
    """A checkout without the reading's compiled kernels (a fresh clone) compiles them once, in the background, while
    the workers collect: otherwise each process that reads a curve before the cache holds them compiles them again
    (17 CPU-s each; servers, the command line and both workers start at once), as a first `curve-vae serve` does.
    The same `curve-vae warm-up` an image runs at its build (docs/DEPLOYMENT.md); tests/service/test_startup.py
    watches a first start compile, in a cache of its own."""
    if hasattr(config, "workerinput") or not compiled_kernels()[1]:  # an xdist worker, or compiled already
        return
    config.stash[_KERNELS] = subprocess.Popen(
        [sys.executable, "-m", "curve_vae.cli", "warm-up"], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL
    )


def pytest_unconfigure(config: pytest.Config) -> None:
    warming = config.stash.get(_KERNELS, None)
    if warming is not None and warming.poll() is None:  # a short run: what is compiled by now stays cached
        warming.terminate()
        warming.wait()


def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    for item in items:
        if SERVER_FIXTURES & set(getattr(item, "fixturenames", ())):
            item.add_marker(pytest.mark.integration)
    # the longest first, so that the processes finish together: the scopes that take longest (LONGEST), then the
    # rest of training, then servers and browsers
    items.sort(key=_longest_first)


#: The scopes (a module, or a class of one) that take longest, the longest first: each 30-150 s of one process in a
#: full run here (`pytest --durations=40`). xdist hands out scopes in this order; one started last would leave the
#: other process idle at the end.
LONGEST = (
    "tests/training/test_end_to_end.py",
    "tests/test_readme_cli.py::TestTrainingChain",
    "tests/scripts/test_gpu_stage.py",
    "tests/service/test_server.py",
    "tests/test_readme_cli.py::TestOwnCurvesTrainingChain",
    "tests/bench/test_serve.py",
    "tests/test_readme_cli.py::TestLearnedPartsChain",
    "tests/test_wheel.py",
    "tests/training/test_train.py",
    "tests/curve_vae/commands/test_train.py",
)


def _longest_first(item: pytest.Item) -> tuple[int, int]:
    scope = item.nodeid.rsplit("::", 1)[0]
    rank = LONGEST.index(scope) if scope in LONGEST else len(LONGEST)
    kind = 0 if item.get_closest_marker("slow") else 1 if item.get_closest_marker("integration") else 2
    return rank, kind


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
    return CurveRuntime.load(model_dir, providers="cpu", intra_op_threads=1, cache_bytes=0)


@pytest.fixture(scope="session")
def raw_runtime(raw_model_dir: Path) -> CurveRuntime:
    return CurveRuntime.load(raw_model_dir, providers="cpu", intra_op_threads=1, cache_bytes=0)


@pytest.fixture(scope="session")
def params_runtime(params_model_dir: Path) -> CurveRuntime:
    return CurveRuntime.load(params_model_dir, providers="cpu", intra_op_threads=1, cache_bytes=0)


@pytest.fixture(scope="session")
def closest_runtime(closest_model_dir: Path) -> CurveRuntime:
    return CurveRuntime.load(closest_model_dir, providers="cpu", intra_op_threads=1, cache_bytes=0)


@pytest.fixture(scope="session")
def shipped_runtime() -> CurveRuntime:
    if not (SHIPPED / "manifest.json").is_file():
        pytest.skip("no shipped model: models/manifest.json is absent")
    return CurveRuntime.load(SHIPPED, providers="cpu", intra_op_threads=1, cache_bytes=0)


@pytest.fixture
def make_client(model_dir: Path, runtime: CurveRuntime) -> Iterator[Callable[..., TestClient]]:
    """make_client(**settings) -> a started TestClient; the app shares the session's runtime."""
    clients: list[TestClient] = []

    def make(*, share_runtime: bool = True, **overrides: object) -> TestClient:
        settings = Settings(**{"model_dir": model_dir, **overrides})
        client = TestClient(create_app(settings, runtime=runtime if share_runtime else None))
        client.__enter__()
        clients.append(client)
        wait_ready(client)  # a runtime of its own warms up in the background (service.app._warm_then_serve)
        return client

    yield make
    for client in clients:
        client.__exit__(None, None, None)


@pytest.fixture
def client(make_client: Callable[..., TestClient]) -> TestClient:
    return make_client()


@pytest.fixture
def curves() -> Callable[..., np.ndarray]:
    return bspline_curves


@pytest.fixture
def server_factory() -> Iterator[Callable[..., LiveServer]]:
    """server_factory(*cli_args) -> a LiveServer, stopped at the end of the test."""
    servers: list[LiveServer] = []

    def start(*args: str, env: dict[str, str] | None = None) -> LiveServer:
        servers.append(spawn_server(*args, env=env))
        return servers[-1]

    yield start
    for server in servers:
        server.stop()


@pytest.fixture(scope="module")
def shipped_server() -> Iterator[LiveServer]:
    """`curve-vae serve` on the shipped model, for tests of what users see (the README's answers)."""
    yield from shipped_live_server()


@pytest.fixture(scope="session")
def live_server(model_dir: Path) -> Iterator[LiveServer]:
    with spawn_server("--model-dir", str(model_dir), "--providers", "cpu", "--max-body-bytes", "200000") as server:
        yield server
