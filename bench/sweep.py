"""One setting swept: B (single-curve default requests, 16 connections) against one server per set of flags, each
started afresh with the encoding cache off, in the order given; `--with-a` also A (128-curve requests, 2
connections). Where bench.serve compares the service's defaults with a few fixed variants, this tries values.

    .venv/bin/python -m bench.sweep "--workers 1 --gil-switch-ms 5" "--workers 1 --gil-switch-ms 2" \\
        "--workers 1 --gil-switch-ms 1" "--workers 1 --gil-switch-ms 0.5" --seconds 8

Servers run one at a time on this machine's cores beside wrk, so compare rows of one run, not runs.
"""

from __future__ import annotations

import argparse
import json
import urllib.request
from pathlib import Path

from prometheus_client.parser import text_string_to_metric_families

from bench.ceiling import posted
from bench.serve import NO_CACHE, ROOT, Server, json_body, wrk


def sweep(flag_sets: list[str], *, seconds: float, with_a: bool, model_dir: Path) -> list[dict]:
    """Per flag set: GET /model's `execution` and its B (and A) runs, as bench.serve.wrk reports them."""
    single, many = json_body(posted(1, seed=1)), json_body(posted(128, seed=2))
    rows = []
    for flags in flag_sets:
        server = Server(model_dir, *flags.split(), env=NO_CACHE)
        try:
            with urllib.request.urlopen(f"{server.url}/model", timeout=30) as r:  # what the server says it runs
                row = {"flags": flags, "execution": json.loads(r.read())["execution"]}
            wrk(server, "/reconstruct", single, "application/json", connections=16, seconds=1)  # warmed up
            before = _coalesced(server)
            row["B"] = wrk(server, "/reconstruct", single, "application/json", connections=16, seconds=seconds)
            jobs, batches = (a - b for a, b in zip(_coalesced(server), before))
            row["B"]["requests_a_batch"] = jobs / batches if batches else None
            if with_a:
                row["A"] = wrk(server, "/reconstruct", many, "application/json", connections=2, seconds=seconds)
        finally:
            server.stop()
        rows.append(row)
        print(_line(row), flush=True)
    return rows


def _coalesced(server: Server) -> tuple[float, float]:
    """Requests read in coalesced batches so far, and the batches (`curve_vae_coalesced_requests` in /metrics, the
    worker this scrape reaches; with --workers 1, the only one)."""
    with urllib.request.urlopen(f"{server.url}/metrics", timeout=30) as r:
        text = r.read().decode()
    value = {
        s.name: s.value
        for family in text_string_to_metric_families(text)
        if family.name == "curve_vae_coalesced_requests"
        for s in family.samples
    }
    return value.get("curve_vae_coalesced_requests_sum", 0.0), value.get("curve_vae_coalesced_requests_count", 0.0)


def _line(row: dict) -> str:
    b = row["B"]
    batch = "—" if b["requests_a_batch"] is None else f"{b['requests_a_batch']:.1f}"
    cpu = b["server_cpu_ms_per_request"]
    text = f"| `{row['flags']}` | {b['rps']:.0f}/s | {b['p50_ms']:.0f} ms | {cpu:.2f} ms | {batch} |"
    if "A" in row:
        text += f" {row['A']['rps'] * 128:.0f} curves/s |"
    return text


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("flags", nargs="+", help='a server\'s flags, quoted: "--workers 1 --gil-switch-ms 2"')
    p.add_argument("--seconds", type=float, default=8.0, help="length of each wrk run (default: 8)")
    p.add_argument("--with-a", action="store_true", help="also 128-curve requests on 2 connections")
    p.add_argument("--model-dir", type=Path, default=ROOT / "models")
    a = p.parse_args()
    print("| flags | B | B p50 | server CPU a B request | B requests a batch |" + (" A |" if a.with_a else ""))
    print("|---|---|---|---|---|" + ("---|" if a.with_a else ""))
    sweep(a.flags, seconds=a.seconds, with_a=a.with_a, model_dir=a.model_dir)


if __name__ == "__main__":
    main()
