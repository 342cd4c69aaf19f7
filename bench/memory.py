"""The server's memory once its encoding cache is full: a real uvicorn server (the app) in this process, client
threads posting new curves with the one-pass reading (/reconstruct, /interpolate, /encode), the resident memory every
30 s and its slope after the cache fills; with --trace, tracemalloc started once it is full and the growth of
traced (Python and numpy) memory by line between the first and last snapshots.

    .venv/bin/python -m bench.memory --minutes 5                          # the slope
    MALLOC_ARENA_MAX=2 .venv/bin/python -m bench.memory --minutes 5       # the same with two malloc arenas
    .venv/bin/python -m bench.memory --minutes 7 --trace                  # where Python memory grows

tracemalloc's own bookkeeping grows the resident memory by itself (~11 MiB/min here), so read the slope from a run
without --trace and the lines from one with it. Traffic goes to 127.0.0.1 only.
"""

from __future__ import annotations

import argparse
import gc
import random
import threading
import time
import tracemalloc
from pathlib import Path

import httpx
import numpy as np
import uvicorn

from curve_vae.geometry import random_control_points, sample_bspline
from curve_vae.service.app import create_app
from curve_vae.service.live import free_port
from curve_vae.service.settings import Settings

ROOT = Path(__file__).resolve().parents[1]
ONE_PASS = {"pose": "canonical", "spacing": "parameter"}


def _client(url: str, seed: int, stop: float) -> None:
    rng, pick = np.random.default_rng(seed), random.Random(seed)
    with httpx.Client(base_url=url, timeout=60) as c:
        while time.time() < stop:
            curves = (sample_bspline(random_control_points(rng, 4), 161) * 0.05 - 3).round(4).tolist()
            body, k = {"curves": curves, **ONE_PASS}, pick.random()
            if k < 0.6:
                c.post("/reconstruct", json=body)
            elif k < 0.8:
                c.post("/interpolate", json={**body, "curves": curves[:2], "steps": 5})
            else:
                c.post("/encode", json=body)


def _rss_mib() -> float:
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * 4096 / 2**20


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--minutes", type=float, default=5.0, help="length of the run (default: 5)")
    p.add_argument("--cache-mib", type=float, default=4.0, help="the encoding cache's bound (default: 4: full soon)")
    p.add_argument("--clients", type=int, default=4, help="client threads (default: 4)")
    p.add_argument("--trace", action="store_true", help="tracemalloc once the cache is full, growth by line")
    a = p.parse_args()
    app = create_app(Settings(model_dir=ROOT / "models", cache_bytes=int(a.cache_mib * 2**20)))
    port = free_port()
    server = uvicorn.Server(uvicorn.Config(app, host="127.0.0.1", port=port, log_level="warning", access_log=False))
    threading.Thread(target=server.run, daemon=True).start()
    while not server.started:
        time.sleep(0.1)
    start, stop = time.time(), time.time() + a.minutes * 60
    clients = [threading.Thread(target=_client, args=(f"http://127.0.0.1:{port}", i, stop)) for i in range(a.clients)]
    for c in clients:
        c.start()
    full: list[tuple[float, float, tracemalloc.Snapshot | None]] = []
    while time.time() < stop - 5:
        time.sleep(30)
        cache = app.state.runtime.cache
        if cache.size > 0.95 * cache.max_bytes:
            if a.trace and not tracemalloc.is_tracing():
                tracemalloc.start(10)
            gc.collect()
            full.append((time.time() - start, _rss_mib(), tracemalloc.take_snapshot() if a.trace else None))
        print(
            f"{time.time() - start:.0f} s: {_rss_mib():.1f} MiB resident, cache {cache.size / 2**20:.2f} MiB",
            flush=True,
        )
    for c in clients:
        c.join()
    server.should_exit = True
    if len(full) < 3:
        raise SystemExit("the cache did not fill in time: a longer run or a smaller --cache-mib")
    (t0, r0, s0), (t1, r1, s1) = full[1], full[-1]
    minutes = (t1 - t0) / 60
    print(
        f"after the cache filled: {r0:.1f} -> {r1:.1f} MiB over {minutes:.1f} min ({(r1 - r0) / minutes:.2f} MiB/min)"
    )
    if s0 is not None and s1 is not None:
        stats = s1.compare_to(s0, "lineno")
        grown = sum(s.size_diff for s in stats) / 2**20
        print(f"traced memory: {grown:+.3f} MiB ({grown / minutes:+.3f} MiB/min); the lines that grew most:")
        for s in stats[:10]:
            print(f"  {s.size_diff / 1024:+9.1f} KiB {s.count_diff:+6d} blocks  {s.traceback}")


if __name__ == "__main__":
    main()
