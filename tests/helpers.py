"""What several test modules share that is not a fixture: the repository's paths, curves of the paper's kind, and
servers' flags."""

from __future__ import annotations

import concurrent.futures as cf
import threading
import time
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest

from curve_vae.geometry import random_control_points, sample_bspline
from curve_vae.service.live import LiveServer

ROOT = Path(__file__).resolve().parents[1]
SHIPPED = ROOT / "models"
FIXTURES = ROOT / "tests" / "fixtures"
#: `curve-vae serve` flags for tests of one worker's inference slot and queue (with a worker per CPU, another worker
#: would answer at once)
ONE_SLOT = ("--providers", "cpu", "--workers", "1", "--inference-concurrency", "1")
#: The environment of servers tests start: one worker unless a test asks for more (`--workers 2`, as the tests of
#: workers do). On a 2-core machine a start of two workers costs 5.1 CPU seconds against 2.3 for one (ready after 2.8
#: against 1.7 s), taken from the test beside it.
TEST_SERVER_ENV = {"CURVE_VAE_WORKERS": "1"}


def spawn_server(*flags: str, env: dict[str, str] | None = None) -> LiveServer:
    """`curve-vae serve` with `flags` from the repository's root, one worker unless `flags` or `env` say otherwise."""
    return LiveServer(*flags, env={**TEST_SERVER_ENV, **(env or {})}, cwd=ROOT)


def shipped_live_server(*flags: str) -> Iterator[LiveServer]:
    """`curve-vae serve` on the shipped model with `flags`, ready, stopped when done (a fixture's body); skips where
    the shipped model is absent."""
    if not (SHIPPED / "manifest.json").is_file():
        pytest.skip("no shipped model: models/manifest.json is absent")
    with spawn_server("--model-dir", str(SHIPPED), "--providers", "cpu", *flags) as server:
        yield server


def bspline_curves(count: int, n_points: int = 161, *, seed: int = 0) -> np.ndarray:
    """(count, n_points, 2) curves of the paper's kind, in the 128×128 plane."""
    return sample_bspline(random_control_points(np.random.default_rng(seed), count), n_points)


def natural_fits_asked(runtime, monkeypatch, readings: list) -> list[list[dict]]:
    """For each reading, the options of every natural fit (geometry.natural_readings_of) the reader ran to read one
    half-ellipse-like curve with it: what `Reader._natural_fit` chose."""
    from curve_vae.inference import reader as reader_module

    asked: list[dict] = []
    real = reader_module.natural_readings_of

    def recording(curves, **kw):
        asked.append(kw)
        return real(curves, **kw)

    monkeypatch.setattr(reader_module, "natural_readings_of", recording)
    t = np.linspace(0, np.pi, 80)
    curve = np.c_[np.cos(t), 0.6 * np.sin(t) + 0.1 * np.sin(3 * t)] * 20
    out = []
    for reading in readings:
        asked.clear()
        runtime.reconstruct([curve], reading)
        out.append(list(asked))
    return out


def together(fn, args):
    """fn(arg) for every arg at once, from as many threads (a barrier starts them); the results, or the exceptions,
    in order."""
    start = threading.Barrier(len(args))

    def call(arg):
        start.wait()
        try:
            return fn(arg)
        except Exception as e:
            return e

    with cf.ThreadPoolExecutor(len(args)) as pool:
        return list(pool.map(call, args))


#: How exactly each of the page's file formats gives its curves back, as relative tolerance: SVG writes 10 significant
#: digits, as the command line does; the others the numbers themselves.
EXPORT_TOLERANCE = {"json": 0.0, "csv": 0.0, "svg": 1e-9, "dxf": 0.0}


def wait_ready(client, timeout: float = 120.0) -> None:
    """Poll a started TestClient's /ready until 200: an app that loads its own model warms it up in the background
    (service.app._warm_then_serve), answering 503 "warming up" meanwhile."""
    deadline = time.monotonic() + timeout
    while client.get("/ready").status_code != 200:
        if time.monotonic() > deadline:
            raise TimeoutError(f"not ready after {timeout} s: {client.get('/ready').json()}")
        time.sleep(0.05)
