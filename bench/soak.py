"""Load and soak: concurrent clients send a mix of every endpoint to a real server on loopback, bounded in time.

    .venv/bin/python bench/soak.py --clients 32 --duration 60            # the figures of docs/RELIABILITY.md
    .venv/bin/python bench/soak.py --clients 8 --duration 5              # the short version CI runs
    .venv/bin/python bench/soak.py --clients 32 --duration 600 --fresh   # new curves every request, 10 minutes

Starts `python -m curve_vae.service.server` on a free loopback port (the shipped model unless --model-dir), warms
every endpoint up, reads the server's resident memory, then runs the clients until the time or the
request budget is spent. Each request of the mix has an expected status (bad inputs are part of the
mix and must get their 422): any other answer, or no answer, is an error. Reports requests, errors,
bad inputs tried, p50/p99 latency per kind and overall, and the server's resident memory before and after, read
every --memory-every seconds during the load with the slope of a line through the readings after the first quarter
(`server_rss_slope_mb_per_min`); stops the server with SIGTERM and checks that it exits 0. Exit status 1 on any
error, on memory growth over --max-rss-growth-mb beyond the encoding cache's bound, or on an unclean stop.
Traffic goes to 127.0.0.1 only.
"""

from __future__ import annotations

import argparse
import asyncio
import json
import random
import sys
import threading
import time
from pathlib import Path

import httpx
import numpy as np

from curve_vae.service.live import LiveServer

ROOT = Path(__file__).resolve().parents[1]


def _curves(rng: np.random.Generator, count: int, n: int) -> list:
    from curve_vae.geometry import random_control_points, sample_bspline

    return (sample_bspline(random_control_points(rng, count), n) * 0.05 - 3).round(4).tolist()


def request_mix(seed: int = 0) -> list[tuple[str, str, str, dict | None, int]]:
    """(kind, method, path, body, expected status): what a front-end, a CI pipeline and a script send."""
    rng = np.random.default_rng(seed)
    one, few, three = _curves(rng, 1, 80), _curves(rng, 16, 161), _curves(rng, 3, 50)
    return [
        ("reconstruct-1", "POST", "/reconstruct", {"curves": one, "spacing": "arc_length"}, 200),
        ("reconstruct-16", "POST", "/reconstruct", {"curves": few}, 200),
        ("encode", "POST", "/encode", {"curves": three}, 200),
        ("decode", "POST", "/decode", {"latents": rng.normal(size=(4, 32)).round(3).tolist(), "n_points": 64}, 200),
        ("interpolate-pair", "POST", "/interpolate", {"curves": three[:2], "steps": 5, "output": "both"}, 200),
        ("interpolate-triplet", "POST", "/interpolate", {"curves": three, "steps": 4, "metrics": True}, 200),
        ("sample", "POST", "/sample", {"count": 4, "n_points": 100}, 200),
        ("augment-json", "POST", "/augment", {"curves": three, "count": 32, "mode": "triplet", "seed": 1}, 200),
        ("augment-npy", "POST", "/augment", {"curves": three, "count": 500, "format": "npy", "seed": 2}, 200),
        ("fit", "POST", "/fit", {"curves": three}, 200),
        ("revolve", "POST", "/revolve", {"curve": [[0, 0], [3, 0], [4, 1], [3, 3], [0, 5]], "segments": 48}, 200),
        ("model", "GET", "/model", None, 200),
        ("bad-nan", "POST", "/encode", {"curves": [[[0, 0], [1, "NaN"], [2, 3], [3, 1]]]}, 422),
        ("bad-short", "POST", "/reconstruct", {"curves": [[[0, 0], [1, 1]]]}, 422),
        ("bad-latent", "POST", "/decode", {"latents": [[0.0] * 3]}, 422),
    ]


async def _client(
    http: httpx.AsyncClient,
    mix: list,
    rng: random.Random,
    deadline: float,
    budget: list[int],
    out: list,
    fresh: bool = False,
) -> None:
    order = list(mix)
    rng.shuffle(order)  # each client cycles through every kind, in its own order: a balanced mix
    curves_rng = np.random.default_rng(rng.randrange(2**32))
    i = 0
    while time.monotonic() < deadline and budget[0] > 0:
        budget[0] -= 1
        kind, method, path, body, expected = order[i % len(order)]
        i += 1
        if fresh and body is not None and "curves" in body and not kind.startswith("bad"):
            # curves never seen before: every read is the reading's whole work, and the encoding cache fills
            body = {**body, "curves": _curves(curves_rng, len(body["curves"]), len(body["curves"][0]))}
        start = time.perf_counter()
        try:
            r = await http.request(method, path, json=body)
            content = await r.aread()
            ok = r.status_code == expected and (expected != 200 or len(content) > 0)
            status = r.status_code
        except httpx.HTTPError as e:
            ok, status = False, f"{type(e).__name__}"
        out.append((kind, time.perf_counter() - start, ok, status, expected))


async def _load(url: str, clients: int, duration: float, max_requests: int, seed: int, fresh: bool = False) -> list:
    mix, out, budget = request_mix(seed), [], [max_requests]
    deadline = time.monotonic() + duration
    limits = httpx.Limits(max_connections=clients, max_keepalive_connections=clients)
    async with httpx.AsyncClient(base_url=url, timeout=120, limits=limits) as http:
        await asyncio.gather(
            *(_client(http, mix, random.Random(seed * 1000 + i), deadline, budget, out, fresh) for i in range(clients))
        )
    return out


def _warm_up(url: str, a: argparse.Namespace) -> None:
    """Every route once, before the first memory reading, then a short load of a different seed."""
    for _, method, path, body, _ in request_mix(a.seed):
        httpx.request(method, url + path, json=body, timeout=120)
    # and every inference thread: each has its own session pair, whose memory arena grows on its first large
    # runs (~100 MB for the shipped model's second pair); that is a one-time cost, not a leak to measure
    asyncio.run(_load(url, a.clients, min(2.0, a.duration), a.max_requests, a.seed + 1))


def _traffic_report(clients: int, results: list, wall: float) -> dict:
    """Requests, errors (a few examples), bad inputs tried, and latency overall and per kind of request."""
    lat = np.array([r[1] for r in results]) * 1e3
    errors = [r for r in results if not r[2]]
    kinds = sorted({r[0] for r in results})
    return {
        "clients": clients,
        "duration_s": round(wall, 1),
        "requests": len(results),
        "requests_per_s": round(len(results) / wall, 1),
        "errors": len(errors),
        "error_examples": [f"{k}: got {s}, expected {e}" for k, _, _, s, e in errors[:5]],
        "bad_inputs_tried": sum(1 for r in results if r[4] == 422),
        "latency_ms": {"p50": round(float(np.percentile(lat, 50)), 1), "p99": round(float(np.percentile(lat, 99)), 1)},
        "by_kind": {
            k: {
                "requests": len(v := [r[1] * 1e3 for r in results if r[0] == k]),
                "p50_ms": round(float(np.percentile(v, 50)), 1),
                "p99_ms": round(float(np.percentile(v, 99)), 1),
            }
            for k in kinds
        },
    }


def _sample_memory(server: LiveServer, every: float, stop: threading.Event, out: list) -> None:
    """(seconds since the load began, resident MiB of the server's processes), every `every` seconds."""
    t0 = time.monotonic()
    while not stop.wait(every):
        out.append((time.monotonic() - t0, server.rss_mib()))


def memory_slope(samples: list[tuple[float, float]], *, skip: float = 0.25) -> float:
    """MiB per minute of a least-squares line through the samples after the first `skip` of the run (warm-up: each
    inference thread's arena grows on its first large runs)."""
    if len(samples) < 4:
        return 0.0
    t, mib = np.array(samples).T
    keep = t >= skip * t[-1]
    return float(np.polyfit(t[keep] / 60, mib[keep], 1)[0]) if keep.sum() >= 3 else 0.0


def run(a: argparse.Namespace) -> dict:
    server = LiveServer("--model-dir", a.model_dir, "--providers", "cpu", cwd=ROOT)
    samples: list[tuple[float, float]] = []
    stop = threading.Event()
    try:
        server.wait_ready()
        _warm_up(server.url, a)
        rss_before = server.rss_mib()
        sampler = threading.Thread(target=_sample_memory, args=(server, a.memory_every, stop, samples), daemon=True)
        sampler.start()
        t0 = time.perf_counter()
        results = asyncio.run(_load(server.url, a.clients, a.duration, a.max_requests, a.seed, a.fresh))
        wall = time.perf_counter() - t0
        stop.set()
        sampler.join()
        rss_after = server.rss_mib()
        cache = httpx.get(server.url + "/model", timeout=60).json().get("cache") or {}
    finally:
        stop.set()
        code = server.stop(timeout=60)
        log = server.output()
    return {
        **_traffic_report(a.clients, results, wall),
        "server_rss_mb": {"before": round(rss_before, 1), "after": round(rss_after, 1)},
        "server_rss_slope_mb_per_min": round(memory_slope(samples), 3),
        "server_rss_samples": [[round(t, 1), round(m, 1)] for t, m in samples],
        "server_cache": cache,
        "server_exit_code": code,
        "server_log_has_traceback": "Traceback" in log,
    }


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--clients", type=int, default=32, help="concurrent clients (default: 32)")
    p.add_argument("--duration", type=float, default=60.0, help="seconds of load (default: 60)")
    p.add_argument("--max-requests", type=int, default=200_000, help="stop after this many requests (default: 200000)")
    p.add_argument("--model-dir", default=str(ROOT / "models"), help="the model to serve (default: the shipped one)")
    p.add_argument(
        "--max-rss-growth-mb",
        type=float,
        default=100.0,
        help="allowed memory growth beyond the encoding cache's bound (default: 100)",
    )
    p.add_argument("--seed", type=int, default=0, help="seed of the request mix and the clients' choices")
    p.add_argument(
        "--fresh",
        action="store_true",
        help="new curves in every request (default: the mix's curves, which the encoding cache answers after the "
        "first time)",
    )
    p.add_argument("--memory-every", type=float, default=5.0, help="seconds between memory readings (default: 5)")
    p.add_argument("--out", default="", help="also write the report as JSON here")
    a = p.parse_args(argv)
    report = run(a)
    print(json.dumps(report, indent=2))
    if a.out:
        Path(a.out).write_text(json.dumps(report, indent=2) + "\n")
    growth = report["server_rss_mb"]["after"] - report["server_rss_mb"]["before"]
    # the encoding cache may fill to its bound by design: that much growth is allowed on top
    allowed = a.max_rss_growth_mb + report["server_cache"].get("max_bytes", 0) / 2**20
    ok = (
        report["errors"] == 0
        and growth <= allowed
        and report["server_exit_code"] == 0
        and not report["server_log_has_traceback"]
    )
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
