"""How soon a freshly started service answers: seconds until `/ready` answers 200 (every worker warmed up), then the
time of each of the first single-curve default requests, each on a new connection (so the workers share them out).

    .venv/bin/python scripts/first_request.py                       # an empty numba cache: a new container's start
    .venv/bin/python scripts/first_request.py --cache-dir /tmp/nc   # run twice with one directory: the second start
    NUMBA_CACHE_DIR=/tmp/seed .venv/bin/curve-vae warm-up            # a cache compiled at an image's build, then
    .venv/bin/python scripts/first_request.py --seed /tmp/seed      # a new container's start with it (copied in)

The reading's compiled kernels (numba) compile into NUMBA_CACHE_DIR; the service's warm-up (inference.runtime
`CurveRuntime.warm_up`) compiles them, or loads them from that cache, while the server already answers (/health 200,
/ready 503 "warming up"), before `/ready` answers 200. Printed: when the port first answered, when /ready said 200.
NUMBA_CPU_NAME in the environment (`generic`: a cache any x86-64 host can load) passes to the server.
"""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
import time
import urllib.request
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from bench.ceiling import posted  # noqa: E402
from curve_vae.inference.model.cpus import available_cpus  # noqa: E402
from service.live import LiveServer  # noqa: E402


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--cache-dir", type=Path, help="NUMBA_CACHE_DIR (default: a new, empty directory)")
    p.add_argument("--requests", type=int, default=6)
    p.add_argument("--model-dir", type=Path, default=ROOT / "models")
    p.add_argument("--seed", type=Path, help="CURVE_VAE_KERNEL_CACHE_SEED: a cache compiled by `curve-vae warm-up`")
    a = p.parse_args()
    cache = a.cache_dir or Path(tempfile.mkdtemp(prefix="numba-cache-"))
    body = json.dumps({"curves": posted(1, seed=1).tolist()}).encode()
    start = time.perf_counter()
    env = {"CURVE_VAE_CACHE_BYTES": "0", "NUMBA_CACHE_DIR": str(cache)}
    if a.seed:
        env["CURVE_VAE_KERNEL_CACHE_SEED"] = str(a.seed)
    server = LiveServer("--model-dir", str(a.model_dir), "--providers", "cpu", env=env, cwd=ROOT, capture=True)
    try:
        while True:
            try:
                urllib.request.urlopen(f"{server.url}/health", timeout=1).close()
                break
            except OSError:
                time.sleep(0.05)
        print(f"answering after {time.perf_counter() - start:.1f} s")
        server.wait_ready(workers=available_cpus())  # the service's default: a worker a CPU
        print(f"ready after {time.perf_counter() - start:.1f} s (numba cache {cache})")
        for k in range(a.requests):
            headers = {"Content-Type": "application/json", "Connection": "close"}
            t = time.perf_counter()
            with urllib.request.urlopen(urllib.request.Request(f"{server.url}/reconstruct", body, headers)) as r:
                r.read()
            print(f"request {k + 1}: {1000 * (time.perf_counter() - t):.1f} ms")
    finally:
        server.stop()


if __name__ == "__main__":
    main()
