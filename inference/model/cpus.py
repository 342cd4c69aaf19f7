"""How many CPUs this process may use, and the onnxruntime threads per inference that fill them without more.

onnxruntime left to itself (intra_op_num_threads 0) starts one thread per core of the host, whatever CPU
quota a container has, and its threads spin while they wait: in a pod limited to 2 CPUs on a 64-core node,
two concurrent inferences would run 128 spinning threads on 2 CPUs' worth of time. So the service sizes
them itself: the CPUs it may use (the cgroup's CPU quota, and the CPUs it may be scheduled on), divided
among the worker processes and the inferences each runs at once. Torch-free; read at startup only.

The same holds for the BLAS library under numpy and scipy (OpenBLAS in their wheels): it starts a thread per core
for each small matrix product of the reading (the ranker's and the spacing guesser's convolutions, the fit's
solves), and on 2 cores it doubled the CPU time of a default single-curve request (36.2 ms against 17.6 ms, about
the same wall time: `python -m bench.profile_one --reading default` without and with `--blas-threads 1`) while the
other inference waited. `limit_blas_threads` gives it the threads of one inference.
"""

from __future__ import annotations

import math
import os
from pathlib import Path
from typing import Any

from curve_vae.inference.model.sessions import SessionConfig

CGROUP = Path("/sys/fs/cgroup")


def cgroup_cpus(root: Path = CGROUP) -> float | None:
    """This cgroup's CPU quota in CPUs (cgroup v2 `cpu.max`, else v1 `cpu.cfs_quota_us` / `cpu.cfs_period_us`);
    None where there is no quota."""
    try:
        quota, period = (root / "cpu.max").read_text().split()[:2]
        return None if quota == "max" else int(quota) / int(period)
    except (OSError, ValueError):
        pass
    try:
        quota_us = int((root / "cpu" / "cpu.cfs_quota_us").read_text())
        period_us = int((root / "cpu" / "cpu.cfs_period_us").read_text())
    except (OSError, ValueError):
        return None
    return quota_us / period_us if quota_us > 0 and period_us > 0 else None


def available_cpus(root: Path = CGROUP) -> int:
    """Whole CPUs this process may use: those it may be scheduled on, capped by the cgroup quota (rounded down:
    1.5 CPUs of quota run 1 thread flat out rather than 2 throttled), at least 1."""
    try:
        cpus = len(os.sched_getaffinity(0))
    except AttributeError:  # not on Linux
        cpus = os.cpu_count() or 1
    quota = cgroup_cpus(root)
    if quota is not None:
        cpus = min(cpus, math.floor(quota))
    return max(1, cpus)


#: The fewest inferences a worker runs at once by default. The default reading holds the GIL for most of a request
#: but not in onnxruntime, so a second inference keeps the worker's core busy while the first runs its graphs, and a
#: large request does not hold up a small one, nor do two connections the kernel hashed to one worker: on 2 cores,
#: 128-curve default requests on 2 connections ran at 81 curves/s with one inference a worker (both connections on
#: one worker, the other idle) against 164 with two; single curves about alike, 105 requests/s with one a worker and
#: 112 with two in an earlier run (docs/BENCHMARKS.md, service 0.18.0).
MIN_SLOTS = 2


def worker_count(settings: Any, cpus: int | None = None) -> int:
    """Worker processes: `settings.workers` where set; for 0, one per CPU this process may use. The default reading
    holds the GIL for most of a request, so one process uses little more than one core (docs/DEPLOYMENT.md)."""
    if settings.workers:
        return int(settings.workers)
    return available_cpus() if cpus is None else cpus


def inference_slots(settings: Any, cpus: int | None = None) -> int:
    """Inferences one worker runs at once: `settings.inference_concurrency` where set; for 0, the CPUs shared
    out among the workers, at least MIN_SLOTS."""
    if settings.inference_concurrency:
        return int(settings.inference_concurrency)
    cpus = available_cpus() if cpus is None else cpus
    return max(MIN_SLOTS, cpus // worker_count(settings, cpus))


def coalescing_readers(settings: Any, cpus: int | None = None) -> int:
    """Batches of coalesced requests one worker reads at once (service.deps): one a CPU of the worker, at
    most its inference slots. Fewer than the slots: two batches sharing a core cost more than one of both."""
    cpus = available_cpus() if cpus is None else cpus
    return max(1, min(inference_slots(settings, cpus), cpus // worker_count(settings, cpus)))


def threads_per_inference(settings: Any, cpus: int | None = None) -> int:
    """`settings.intra_op_threads` where set; for 0, the CPUs shared out: workers × inference slots
    inferences run at once, each on this many threads (at least 1)."""
    if settings.intra_op_threads:
        return int(settings.intra_op_threads)
    cpus = available_cpus() if cpus is None else cpus
    return max(1, cpus // (worker_count(settings, cpus) * inference_slots(settings, cpus)))


def limit_blas_threads(threads: int) -> int:
    """Cap every BLAS library this process has loaded (threadpoolctl) at `threads` threads, process-wide, and
    return the most any of them now runs (0 where none is loaded). Call it once the runtime has loaded, so that
    numpy's and scipy's libraries are both there to cap."""
    from threadpoolctl import threadpool_info, threadpool_limits

    threadpool_limits(limits=threads, user_api="blas")
    return blas_threads(threadpool_info())


def blas_threads(info: list[dict[str, Any]] | None = None) -> int:
    """The most threads any loaded BLAS library runs (threadpoolctl's report; 0 where none is loaded)."""
    if info is None:
        from threadpoolctl import threadpool_info

        info = threadpool_info()
    return max((int(lib["num_threads"]) for lib in info if lib["user_api"] == "blas"), default=0)


def session_config(settings: Any, cpus: int | None = None) -> SessionConfig:
    """The onnxruntime sessions of one worker: threads and spinning from the settings, one pair per inference
    slot unless `settings.sessions` says otherwise."""
    cpus = available_cpus() if cpus is None else cpus
    return SessionConfig(
        intra_op_threads=threads_per_inference(settings, cpus),
        inter_op_threads=settings.inter_op_threads,
        spinning=settings.spinning,
        sessions=settings.sessions or inference_slots(settings, cpus),
    )
