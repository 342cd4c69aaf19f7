"""Serving benchmark: the real server under wrk, as ratios to the in-process onnxruntime ceiling.

    apt-get install -y wrk                       # once: the load generator (Debian package)
    .venv/bin/python -m bench.serve              # ~5 minutes on 2 cores; --seconds 10 per load run
    .venv/bin/python -m bench.serve --seconds 1 --runs B   # the test suite's smoke run

It starts `python -m curve_vae.service.server` (uvicorn, the service's defaults unless a run says otherwise) on a
loopback port for each configuration, drives it with wrk (POST bodies from a small Lua script, bench/post.lua), and
reads the server's CPU time from /proc (all its processes), so the server's cost per request shows apart from wrk's.
The headline rows A and B are the request a user sends: no pose or spacing fields, the paper's curves as a caller
posts them (turned, mirrored or reversed, in pixels, spaced by arc length); beside them the fast path (pose "as_is",
spacing "parameter") and, one connection at a time, the search. wrk posts one body again and again, so those
servers run without the encoding cache (every request read afresh); B_cached, against a server of its own with the
cache on, shows what a re-posted curve costs.
The report is a Markdown section (`bench.report`; printed, and written with --markdown FILE) and JSON (--json FILE).
"""

from __future__ import annotations

import argparse
import functools
import io
import json
import os
import platform
import shutil
import subprocess
import sys
import tempfile
import time
import urllib.request
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from bench import ceiling
from bench.report import markdown
from curve_vae.inference.model.cpus import available_cpus
from curve_vae.service.live import LiveServer

ROOT = Path(__file__).resolve().parent.parent
LUA = Path(__file__).resolve().parent / "post.lua"
RUNS = (
    "A",
    "B",
    "B_cached",
    "one_pass",
    "B_npy",
    "latency",
    "interpolate",
    "augment",
    "spinning",
    "access_log",
    "one_worker",
    "one_thread",
    "one_session",
    "micro_batch",
    "switch_5ms",
    "C",
)


# --------------------------------------------------------------------------- the server


class Server(LiveServer):
    """`python -m curve_vae.service.server` on a free loopback port with extra flags and environment, ready when
    made."""

    def __init__(self, model_dir: Path, *flags: str, env: dict[str, str] | None = None) -> None:
        super().__init__("--model-dir", str(model_dir), "--providers", "cpu", *flags, env=env, cwd=ROOT, capture=False)
        workers = int(flags[flags.index("--workers") + 1]) if "--workers" in flags else 0
        workers = workers or available_cpus()  # the service's default: one per CPU
        try:
            self.wait_ready(workers=workers)  # wrk's connections are shared out as they open
        except BaseException:
            self.stop()
            raise


# --------------------------------------------------------------------------- load


def wrk(server: Server, path: str, body: bytes, content_type: str, *, connections: int, seconds: float) -> dict:
    """Drive `path` with wrk for `seconds`; requests/s, latency percentiles (ms), errors, server CPU per request."""
    with tempfile.NamedTemporaryFile(suffix=".body", delete=False) as f:
        f.write(body)
    env = {**os.environ, "BENCH_BODY": f.name, "BENCH_CONTENT_TYPE": content_type}
    threads = min(connections, 2)
    cmd = ["wrk", f"-t{threads}", f"-c{connections}", f"-d{max(1, round(seconds))}s", "--timeout", "30s"]
    cmd += ["-s", str(LUA), f"{server.url}{path}"]
    before, wrk_before, busy_before = server.cpu_seconds(), _children_cpu(), _busy_cpu()
    try:
        out = subprocess.run(cmd, env=env, capture_output=True, text=True, check=True, timeout=seconds + 60).stdout
    finally:
        os.unlink(f.name)
    after, wrk_cpu, busy = server.cpu_seconds(), _children_cpu() - wrk_before, _busy_cpu() - busy_before
    result = json.loads(out.strip().splitlines()[-1])  # the line post.lua's done() prints
    requests = max(result["requests"], 1)
    result["rps"] = result["requests"] / (result["duration_us"] / 1e6)
    result["p50_ms"], result["p99_ms"] = result.pop("p50_us") / 1e3, result.pop("p99_us") / 1e3
    cpu = {pid: after[pid] - before.get(pid, 0.0) for pid in after}
    result["server_cpu_ms_per_request"] = sum(cpu.values()) / requests * 1e3
    result["wrk_cpu_ms_per_request"] = wrk_cpu / requests * 1e3
    # CPU seconds of everything else on the machine during the run: other people's jobs show here
    result["other_cpu_s"] = max(0.0, busy - sum(cpu.values()) - wrk_cpu)
    result["cpu_s_by_process"] = {str(pid): round(s, 2) for pid, s in cpu.items()}
    result["server_rss_mib"] = server.rss_mib()  # resident memory of all its processes, after the run
    if result["errors"] or result["non_2xx"]:
        print(f"  ! {path}: {result['errors']} socket errors, {result['non_2xx']} non-2xx answers", file=sys.stderr)
    return result


def _busy_cpu() -> float:
    """CPU seconds the whole machine has been busy (all cores; /proc/stat), to tell other work during a run."""
    fields = [int(v) for v in Path("/proc/stat").read_text().split("\n", 1)[0].split()[1:]]
    idle = fields[3] + fields[4]  # idle, iowait
    return (sum(fields[:8]) - idle) / os.sysconf("SC_CLK_TCK")


def _children_cpu() -> float:
    """CPU seconds of this process's finished children (wrk's, once it has exited)."""
    import resource

    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def json_body(curves: np.ndarray, **fields: Any) -> bytes:
    return json.dumps({"curves": curves.tolist(), **fields}).encode()


def npy_body(a: np.ndarray) -> bytes:
    buf = io.BytesIO()
    np.save(buf, a.astype(np.float32))
    return buf.getvalue()


def post(url: str, body: bytes) -> bytes:
    req = urllib.request.Request(url, data=body, headers={"Content-Type": "application/json"})
    with urllib.request.urlopen(req, timeout=600) as r:
        return r.read()


def augment(server: Server, seeds: np.ndarray, count: int) -> dict[str, float]:
    """Seconds for `count` curves from /augment: JSON paged by offset (max_curves a page), one .npy stream, and the
    client's iterator (curve_vae.client.Client.augment_chunks: .npy chunks of 4096, parsed into arrays)."""
    from curve_vae.client import Client

    page = 256
    start = time.perf_counter()
    got = 0
    for offset in range(0, count, page):
        n = min(page, count - offset)
        body = json_body(seeds, count=n, offset=offset, seed=1)
        got += len(json.loads(post(f"{server.url}/augment", body))["curves"])
    json_s = time.perf_counter() - start
    start = time.perf_counter()
    data = post(f"{server.url}/augment", json_body(seeds, count=count, seed=1, format="npy"))
    streamed = np.load(io.BytesIO(data))
    npy_s = time.perf_counter() - start
    with Client(server.url) as c:
        c.model()
        start = time.perf_counter()
        chunks = [a.stacked() for a in c.augment_chunks(list(seeds), count, seed=1, chunk=4096)]
        client_s = time.perf_counter() - start
    assert got == count and streamed.shape[0] == count
    assert np.array_equal(np.concatenate(chunks), streamed)  # the same curves, whatever the chunks
    return {
        "count": count,
        "json_s": json_s,
        "npy_s": npy_s,
        "client_s": client_s,
        "json_cps": count / json_s,
        "npy_cps": count / npy_s,
        "client_cps": count / client_s,
    }


# --------------------------------------------------------------------------- the report


def machine() -> dict[str, Any]:
    import onnxruntime
    import uvicorn

    cpu = next((ln.split(":", 1)[1].strip() for ln in open("/proc/cpuinfo") if ln.startswith("model name")), "?")
    return {
        "cpu": cpu,
        "cores": len(os.sched_getaffinity(0)),
        "python": platform.python_version(),
        "onnxruntime": onnxruntime.__version__,
        "uvicorn": uvicorn.__version__,
        "load_before": os.getloadavg(),
    }


VARIANTS = {  # run as B (the default request), each against a server started with these flags, no cache
    "spinning": (["--spinning", "true"], "B with onnxruntime's spin-waiting on"),
    "access_log": (["--access-log", "true"], "B with the access log on"),
    "one_worker": (["--workers", "1"], "B (and A, where asked) in one worker process, as before service 0.18.0"),
    "switch_5ms": (["--workers", "1", "--gil-switch-ms", "5"], "B in one worker, Python's own GIL switch interval"),
    "one_thread": (["--inference-concurrency", "1"], "B (and A, where asked) with one inference thread a worker"),
    "one_session": (["--sessions", "1"], "B with one session pair shared by both inference threads"),
    "micro_batch": (["--micro-batch", "true"], "B with micro-batching (32 rows, 2 ms)"),
}


def run(a: argparse.Namespace) -> dict[str, Any]:
    if shutil.which("wrk") is None:
        sys.exit("bench.serve: wrk is not installed: apt-get install -y wrk")
    model_dir, secs = Path(a.model_dir), a.seconds
    runs = set(a.runs)
    command = "python -m bench.serve " + " ".join(sys.argv[1:])
    report: dict[str, Any] = {"machine": machine(), "seconds": secs, "command": command}
    print("in-process ceiling ...", file=sys.stderr)
    report["inprocess"] = ceiling.measure(model_dir, seconds=min(secs, 5.0), eager="C" in runs)
    load = functools.partial(_load, report, secs)
    _default_server_runs(load, report, model_dir, runs, a.augment_count)
    _variant_runs(load, model_dir, runs)
    report["machine"]["load_after"] = os.getloadavg()
    _ceiling_again(report, model_dir, secs)
    return report


def _load(
    report: dict[str, Any],
    secs: float,
    name: str,
    server: Server,
    path: str,
    body: bytes,
    ctype: str = "application/json",
    c: int = 16,
    at_least: float = 0.0,
) -> dict[str, Any]:
    """One wrk run of `c` connections against `server` for `secs` (or `at_least` seconds, where one request takes
    seconds: wrk counts only the requests it saw finish), its result stored in the report under `name`."""
    print(f"{name} ...", file=sys.stderr)
    report[name] = wrk(server, path, body, ctype, connections=c, seconds=max(secs, at_least))
    return report[name]


FAST = {"pose": "as_is", "spacing": "parameter", "looks": 0}  # the fast path: the curve read as it is listed
ONE_PASS = {"pose": "canonical", "spacing": "parameter", "looks": 0}  # one encoding per curve, canonical pose
SEARCH = {"pose": "search", "spacing": "search"}  # every pose and spacing candidate, the closest kept
NO_CACHE = {"CURVE_VAE_CACHE_BYTES": "0"}  # wrk posts one body again and again: without this, every curve is a hit


def _default_server_runs(
    load: Callable[..., dict[str, Any]], report: dict[str, Any], model_dir: Path, runs: set[str], augment_count: int
) -> None:
    """The runs against a server with the service's defaults but no encoding cache (every request read afresh: the
    headline A and B are the default request, no pose or spacing fields, curves in a caller's frame, beside the fast
    path), then B against one with its cache (the same curve every time: what a re-posted curve costs)."""
    one, many = ceiling.posted(1, seed=1), ceiling.posted(128, seed=2)
    server = Server(model_dir, env=NO_CACHE)
    try:
        if "A" in runs:
            # a default 128-curve request takes seconds on 2 cores: A runs long enough to see a dozen finish
            for name, fields, at_least in (("A", {}, 60.0), ("A_fast", FAST, 0.0)):
                r = load(name, server, "/reconstruct", json_body(many, **fields), c=2, at_least=at_least)
                r["curves_per_s"] = r["rps"] * 128
        if "B" in runs:
            load("B", server, "/reconstruct", json_body(one))
            load("B_fast", server, "/reconstruct", json_body(one, **FAST))
        if "one_pass" in runs:
            r = load("A_one", server, "/reconstruct", json_body(many, **ONE_PASS), c=2)
            r["curves_per_s"] = r["rps"] * 128
            load("B_one", server, "/reconstruct", json_body(one, **ONE_PASS))
            load("latency_1_one", server, "/reconstruct", json_body(one, **ONE_PASS), c=1)
        if "B_npy" in runs:
            load("B_npy", server, "/reconstruct", npy_body(one), "application/x-npy")
        if "latency" in runs:
            load("latency_1", server, "/reconstruct", json_body(one), c=1)
            load("latency_1_fast", server, "/reconstruct", json_body(one, **FAST), c=1)
            load("latency_1_search", server, "/reconstruct", json_body(one, **SEARCH), c=1)
        if "interpolate" in runs:
            load("interpolate", server, "/interpolate", json_body(ceiling.posted(2, seed=3), steps=5))
        if "augment" in runs:
            print("augment ...", file=sys.stderr)
            report["augment"] = augment(server, ceiling.posted(8, seed=4), augment_count)
    finally:
        server.stop()
    if "B_cached" in runs:
        cached = Server(model_dir)
        try:
            load("B_cached", cached, "/reconstruct", json_body(one))
        finally:
            cached.stop()


WITH_A = ("one_worker", "one_thread")  # variants also run as A when A is asked for
ONE_PASS_VARIANTS = ("micro_batch", "one_worker")  # variants also run with one-pass bodies when one_pass is asked for
ONE_PASS_NAMES = tuple(f"{v}_one" for v in ONE_PASS_VARIANTS)


def _variant_runs(load: Callable[..., dict[str, Any]], model_dir: Path, runs: set[str]) -> None:
    """B against a server of each asked-for variant (VARIANTS), one server each."""
    single = json_body(ceiling.posted(1, seed=1))
    for name, (flags, _) in VARIANTS.items():
        if name in runs:
            server = Server(model_dir, *flags, env=NO_CACHE)
            try:
                if name in WITH_A and "A" in runs:  # large requests on 2 connections, hashed to the workers
                    r = load(
                        f"A_{name}", server, "/reconstruct", json_body(ceiling.posted(128, seed=2)), c=2, at_least=60.0
                    )
                    r["curves_per_s"] = r["rps"] * 128
                load(name, server, "/reconstruct", single)
                if name in ONE_PASS_VARIANTS and "one_pass" in runs:  # does sharing graph runs, or one process
                    # (one GIL for the event loop and the inference threads), help or hinder a one-pass request?
                    load(f"{name}_one", server, "/reconstruct", json_body(ceiling.posted(1, seed=1), **ONE_PASS))
            finally:
                server.stop()


def _ceiling_again(report: dict[str, Any], model_dir: Path, secs: float) -> None:
    """The ceiling again at the end: other work on the machine during the first measurement shows as a difference,
    and the better of the two is the ceiling the ratios (each throughput run's curves/s over it) use."""
    inproc = report["inprocess"]
    print("in-process ceiling again ...", file=sys.stderr)
    again = ceiling.measure(model_dir, seconds=min(secs, 5.0), eager=False, details=False)
    inproc["ceiling_at_start"], inproc["ceiling_at_end"] = inproc["ceiling"], again["ceiling"]
    for key in ("default_b128", "per_core_b128"):
        inproc[key] = max(inproc[key], again[key])
    inproc["ceiling"] = top = max(inproc["ceiling"], again["ceiling"])
    for name, x in report.items():
        if name in (
            "A",
            "A_fast",
            "A_one",
            *(f"A_{v}" for v in WITH_A),
            "B",
            "B_fast",
            "B_one",
            "B_npy",
            "B_cached",
            *VARIANTS,
            *ONE_PASS_NAMES,
        ):
            x["ratio"] = x.get("curves_per_s", x["rps"]) / top


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--model-dir", default=str(ROOT / "models"), help="model to serve (default: the shipped one)")
    p.add_argument("--seconds", type=float, default=10.0, help="length of each wrk run (default: 10)")
    p.add_argument("--runs", nargs="+", choices=RUNS, default=list(RUNS), help="which runs (default: all)")
    p.add_argument("--augment-count", type=int, default=10_000, help="curves asked of /augment (default: 10000)")
    p.add_argument("--json", help="write the full results as JSON to this file")
    p.add_argument("--markdown", help="write the Markdown report to this file")
    a = p.parse_args(argv)
    report = run(a)
    text = markdown(report)
    print(text)
    if a.json:
        Path(a.json).write_text(json.dumps(report, indent=1) + "\n")
    if a.markdown:
        Path(a.markdown).write_text(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
