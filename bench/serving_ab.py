"""The default request (no fields but the curves) on this checkout's `curve-vae serve` and another revision's, in one
run, rounds alternating: what a change costs, or what a piece of serving plumbing buys.

Each server runs the shipped model with the encoding cache off, two workers (one a CPU here), and is driven by wrk:
A, 128-curve requests on 2 connections; B, single curves on 16.

    .venv/bin/python -m bench.serving_ab --against 82a174e               # ~4 minutes on 2 cores
    .venv/bin/python -m bench.serving_ab --against 82a174e --rounds 3 --seconds 20 --json out.json

Servers run one after another on the same cores, so compare the rows of one run.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import sys
import time
from pathlib import Path
from typing import Any

from bench.ceiling import posted
from bench.reading_cost import revision_root
from bench.revisions import ROOT
from bench.serve import NO_CACHE, json_body, machine, wrk
from curve_vae.inference.model.cpus import available_cpus
from curve_vae.service.live import LiveServer

KINDS = ("against", "this")


def start(kind: str, revision: str) -> LiveServer:
    """A server of `kind`, ready (every worker warmed up)."""
    workers = str(available_cpus())
    env = {**NO_CACHE, "CURVE_VAE_PROVIDERS": "cpu"}
    if kind == "against":
        root = revision_root(revision)
        env["PYTHONPATH"] = str(root)  # before this checkout's editable install
        args = ("--model-dir", str(root / "tree" / "models"), "--workers", workers)
        server = LiveServer(*args, env=env, cwd=root, capture=False)
    else:
        server = LiveServer("--model-dir", str(ROOT / "models"), "--workers", workers, env=env, cwd=ROOT, capture=False)
    try:
        server.wait_ready(workers=int(workers))
    except BaseException:
        server.stop()
        raise
    return server


def measure(kind: str, revision: str, seconds: float) -> dict[str, Any]:
    single, many = json_body(posted(1, seed=1)), json_body(posted(128, seed=2))
    server = start(kind, revision)
    try:
        wrk(server, "/reconstruct", single, "application/json", connections=16, seconds=2)  # every worker warmed
        out = {}
        for name, body, curves, connections in (("A", many, 128, 2), ("B", single, 1, 16)):
            print(f"{kind}: {name} ...", file=sys.stderr, flush=True)
            r = wrk(server, "/reconstruct", body, "application/json", connections=connections, seconds=seconds)
            out[name] = {
                "curves_per_s": r["rps"] * curves,
                "p50_ms": r["p50_ms"],
                "server_cpu_ms_per_request": r["server_cpu_ms_per_request"],
                "errors": r["errors"] + r["non_2xx"],
                "cpu_s_by_process": r.get("cpu_s_by_process"),
            }
        return out
    finally:
        server.stop()
        time.sleep(1)


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--against", required=True, help="the revision to measure beside this checkout")
    p.add_argument("--rounds", type=int, default=2, help="rounds of the three servers (default 2)")
    p.add_argument("--seconds", type=float, default=15.0, help="each wrk run (default 15)")
    p.add_argument("--json", default="", help="also write the report here")
    a = p.parse_args()
    rows: dict[str, list[dict[str, Any]]] = {k: [] for k in KINDS}
    for _ in range(a.rounds):
        for kind in KINDS:
            rows[kind].append(measure(kind, a.against, a.seconds))
    report: dict[str, Any] = {"machine": machine(), "command": " ".join(sys.argv), "rows": rows}
    print("| server | A: curves/s (each round) | B: requests/s (each round) | A / this | B / this |")
    print("|---|---|---|---|---|")
    median = {k: {n: statistics.median(r[n]["curves_per_s"] for r in rows[k]) for n in "AB"} for k in KINDS}
    for kind in KINDS:
        a_runs = ", ".join(f"{r['A']['curves_per_s']:.0f}" for r in rows[kind])
        b_runs = ", ".join(f"{r['B']['curves_per_s']:.0f}" for r in rows[kind])
        print(
            f"| {kind} | {a_runs} | {b_runs} | {median[kind]['A'] / median['this']['A']:.2f} | "
            f"{median[kind]['B'] / median['this']['B']:.2f} |"
        )
    report["median"] = median
    if a.json:
        Path(a.json).write_text(json.dumps(report, indent=2))


if __name__ == "__main__":
    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
    main()
