"""How a process's threads share its cores: requests a second from one thread and from two, each thread reading its own
requests through one runtime (no cache, one intra-op thread per graph run, numpy's BLAS on one thread, as the
service runs them), with the cores each kept busy and the CPU a request cost. Two threads reach 2× one only where the
reading releases the GIL.

    .venv/bin/python -m bench.threads                      # single-curve default requests
    .venv/bin/python -m bench.threads --curves 128 --seconds 10
    .venv/bin/python -m bench.threads --reading one-pass
"""

from __future__ import annotations

import argparse
import os
import threading
import time
from pathlib import Path

from bench import ceiling
from curve_vae.inference.model.cpus import limit_blas_threads
from curve_vae.inference.model.sessions import SessionConfig
from curve_vae.inference.reading import Reading
from curve_vae.inference.runtime import CurveRuntime

ROOT = Path(__file__).resolve().parents[1]
READINGS = {"default": Reading(), "one-pass": Reading(pose="canonical", spacing="parameter")}


def measure(rt: CurveRuntime, requests: list[list], reading: Reading, threads: int, seconds: float) -> dict[str, float]:
    """Requests a second that `threads` threads answer together, each going through `requests` in turn; and the
    process's CPU time beside it: the cores it kept busy (below `threads`: threads waiting for the GIL) and the CPU a
    request cost (above one thread's: what sharing the cores and handing the GIL round cost)."""
    cpu_before, wall_before = os.times(), time.perf_counter()
    answered = _answered(rt, requests, reading, threads, seconds)
    cpu_after, wall = os.times(), time.perf_counter() - wall_before
    cpu = (cpu_after.user + cpu_after.system) - (cpu_before.user + cpu_before.system)
    return {"rate": answered / wall, "cores_busy": cpu / wall, "cpu_ms_per_request": 1e3 * cpu / max(answered, 1)}


def _answered(rt: CurveRuntime, requests: list[list], reading: Reading, threads: int, seconds: float) -> int:
    done = [0] * threads
    stop = time.perf_counter() + seconds

    def work(k: int) -> None:
        i = k
        while time.perf_counter() < stop:
            rt.reconstruct(requests[i % len(requests)], reading)
            done[k] += 1
            i += threads

    pool = [threading.Thread(target=work, args=(k,)) for k in range(threads)]
    for t in pool:
        t.start()
    for t in pool:
        t.join()
    return sum(done)


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--reading", choices=READINGS, default="default")
    p.add_argument("--curves", type=int, default=1, help="curves a request")
    p.add_argument("--seconds", type=float, default=8.0)
    p.add_argument("--model-dir", type=Path, default=ROOT / "models")
    args = p.parse_args()
    limit_blas_threads(1)
    rt = CurveRuntime.load(args.model_dir, sessions=SessionConfig(intra_op_threads=1), cache_bytes=0)
    callers = list(ceiling.posted(64 * args.curves, seed=3))
    requests = [callers[i : i + args.curves] for i in range(0, len(callers), args.curves)]
    reading = READINGS[args.reading]
    rt.reconstruct(requests[0], reading)  # warm: graphs, compiled code
    one = measure(rt, requests, reading, 1, args.seconds)
    two = measure(rt, requests, reading, 2, args.seconds)
    unit = "requests" if args.curves == 1 else f"{args.curves}-curve requests"
    print(
        f"{args.reading} reading, {unit} a second: one thread {one['rate']:.1f}, two threads {two['rate']:.1f} "
        f"({two['rate'] / one['rate']:.2f}×)"
    )
    for name, m in (("one thread", one), ("two threads", two)):
        print(f"  {name}: {m['cores_busy']:.2f} cores busy, {m['cpu_ms_per_request']:.2f} ms of CPU a request")


if __name__ == "__main__":
    main()
