"""The serving benchmark's report: the Markdown section docs/BENCHMARKS.md quotes, from bench.serve's results."""

from __future__ import annotations

from typing import Any


def _f(x: float | None, digits: int = 2) -> str:
    return "–" if x is None else f"{x:.{digits}f}"


ROW_LABELS = {
    "A": "**A: /reconstruct, 128 curves, the default request**, 2 connections",
    "A_fast": "A, the fast path (pose as_is, spacing parameter)",
    "B": "**B: /reconstruct, 1 curve, the default request**, 16 connections",
    "B_fast": "B, the fast path (pose as_is, spacing parameter)",
    "A_one": "A, one pass (pose canonical, spacing parameter)",
    "B_one": "B, one pass (pose canonical, spacing parameter)",
    "B_npy": "B with a .npy body",
    "B_cached": "B with the encoding cache on (the same curve every time)",
    "latency_1": "/reconstruct, 1 curve, the default request, 1 connection",
    "latency_1_fast": "/reconstruct, 1 curve, the fast path, 1 connection",
    "latency_1_one": "/reconstruct, 1 curve, one pass, 1 connection",
    "latency_1_search": "/reconstruct, 1 curve, the search (pose, spacing search), 1 connection",
    "interpolate": "/interpolate, pair, 5 steps, the default request, 16 connections",
    "spinning": "B, spinning on (`--spinning true`)",
    "access_log": "B, access log on (`--access-log true`)",
    "A_one_worker": "A, one worker (`--workers 1`)",
    "one_worker": "B, one worker (`--workers 1`)",
    "switch_5ms": "B, one worker, Python's own GIL switch interval (`--workers 1 --gil-switch-ms 5`)",
    "A_one_thread": "A, one inference thread a worker (`--inference-concurrency 1`)",
    "one_thread": "B, one inference thread a worker (`--inference-concurrency 1`)",
    "one_session": "B, one session pair for both threads (`--sessions 1`)",
    "micro_batch": "B, micro-batching on (`--micro-batch true`: 32 rows, 2 ms)",
    "micro_batch_one": "B, one pass, micro-batching on",
    "one_worker_one": "B, one pass, one worker (`--workers 1`)",
}


def markdown(r: dict[str, Any]) -> str:
    lines = [*_preamble(r), *_table(r), *_notes(r), *_breakdown(r), *_eager(r["inprocess"])]
    return "\n".join(lines) + "\n"


def _preamble(r: dict[str, Any]) -> list[str]:
    """The machine, the command, and the in-process ceiling."""
    m, ip = r["machine"], r["inprocess"]
    return [
        f"Machine: {m['cpu']}, {m['cores']} cores; Python {m['python']}, onnxruntime {m['onnxruntime']}, "
        f"uvicorn {m['uvicorn']}. Load average before {m['load_before'][0]:.2f}, after {m['load_after'][0]:.2f}. "
        f"Command: `{r['command']}` ({r['seconds']:g} s per load run).",
        "",
        f"In-process ceiling: {ip['ceiling']:.0f} curves/s, the better of: one default session at batch 128, "
        f"{ip['default_b128']:.0f}; one 1-thread session per core in parallel, {ip['per_core_b128']:.0f} "
        f"(measured before the load runs: {ip['ceiling_at_start']:.0f}, after: {ip['ceiling_at_end']:.0f}).",
        "",
    ]


def _table(r: dict[str, Any]) -> list[str]:
    """The table of the load runs, a row each run made."""
    lines = [
        "| run | requests/s | curves/s | ÷ ceiling | p50 ms | p99 ms | server CPU ms/request | wrk CPU ms/request "
        "| other CPU s | non-2xx |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    single = (
        "B",
        "B_fast",
        "B_one",
        "B_npy",
        "B_cached",
        "spinning",
        "access_log",
        "one_worker",
        "switch_5ms",
        "one_thread",
        "one_session",
        "micro_batch",
        "micro_batch_one",
        "one_worker_one",
    )
    for key, label in ROW_LABELS.items():
        if key not in r:
            continue
        x = r[key]
        cps = x.get("curves_per_s", x["rps"] if key in single else None)
        lines.append(
            f"| {label} | {x['rps']:.0f} | {_f(cps, 0)} | {_f(x.get('ratio'))} | {x['p50_ms']:.1f} | "
            f"{x['p99_ms']:.1f} | {x['server_cpu_ms_per_request']:.2f} | {x['wrk_cpu_ms_per_request']:.2f} | "
            f"{x['other_cpu_s']:.1f} | {x['non_2xx'] + x['errors']} |"
        )
    return lines


def _notes(r: dict[str, Any]) -> list[str]:
    """The workers' CPU spread and /augment's times, where those runs were made."""
    lines: list[str] = []
    for key in ("A", "B", "A_one_worker", "one_worker", "A_one_thread", "one_thread"):
        if key in r:
            x = r[key]
            spread = ", ".join(f"{s:.1f}" for s in sorted(x["cpu_s_by_process"].values(), reverse=True))
            memory = (
                f"; resident memory after it, all of them: {x['server_rss_mib']:.0f} MiB"
                if "server_rss_mib" in x
                else ""
            )
            lines += ["", f"Run {key}: CPU seconds per server process (supervisor included): {spread}{memory}."]
    if "augment" in r:
        g = r["augment"]
        lines += [
            "",
            f"/augment, {g['count']:,} curves (8 seeds, the default request): JSON in pages of 256 "
            f"{g['json_s']:.2f} s ({g['json_cps']:.0f} curves/s); one .npy stream {g['npy_s']:.2f} s "
            f"({g['npy_cps']:.0f} curves/s); the client's iterator (`Client.augment_chunks`, .npy chunks of 4096) "
            f"{g['client_s']:.2f} s ({g['client_cps']:.0f} curves/s, {g['client_cps'] / g['npy_cps']:.2f}× the "
            "stream).",
        ]
    return lines


def _breakdown(r: dict[str, Any]) -> list[str]:
    """Where a request's time goes in-process, and what of B's server CPU that leaves to HTTP and the rest."""
    b = r["inprocess"].get("breakdown")
    if not b:
        return []
    lines = [
        "",
        "In-process, one 1-thread session, no cache, ms per request (1 curve / 128 curves): "
        f"encoder + decoder {b['onnx_b1_ms']:.2f} / {b['onnx_b128_ms']:.0f}; "
        f"`CurveRuntime.reconstruct` with the default reading {b['reconstruct_default_b1_ms']:.2f} / "
        f"{b['reconstruct_default_b128_ms']:.0f}, the fast path {b['reconstruct_fast_b1_ms']:.2f} / "
        f"{b['reconstruct_fast_b128_ms']:.0f}, the search {b['reconstruct_search_b1_ms']:.1f} (1 curve); "
        f"JSON parse + validation {b['parse_validate_b1_ms']:.2f} / {b['parse_validate_b128_ms']:.1f}; "
        f"rendering the answer {b['render_b1_ms']:.2f} / {b['render_b128_ms']:.1f}.",
    ]
    if "B" in r:
        own = b["reconstruct_default_b1_ms"]
        server = r["B"]["server_cpu_ms_per_request"]
        rest = server - own - b["parse_validate_b1_ms"]
        of_b = f"Of B's {server:.2f} ms of server CPU per request, {own:.2f} are the runtime's work in isolation"
        if rest >= 0:
            lines.append(
                f"{of_b} and {b['parse_validate_b1_ms']:.2f} JSON; the other {rest:.2f} ms are HTTP, the framework, "
                "the thread hand-offs and inference slowed by sharing the cores with the event loop and wrk."
            )
        else:  # a short or loaded run: the isolated timing (wall time on one thread) came out above the server's CPU
            lines.append(
                f"B's {server:.2f} ms of server CPU per request are less than the runtime's work in isolation "
                f"({own:.2f} ms) and JSON ({b['parse_validate_b1_ms']:.2f}): a run this short or this loaded does not "
                "split the server's cost (`--seconds 10` on a quiet machine does)."
            )
    return lines


def _eager(ip: dict[str, Any]) -> list[str]:
    """C: onnxruntime against torch eager, where it was measured."""
    if ip.get("C_b1") is None:
        return []
    return [
        "",
        "C, onnxruntime ÷ torch eager, encoder + decoder, 1 thread each: "
        f"batch 1 {ip['onnx_1t_b1']:.0f} vs {ip['torch_1t_b1']:.0f} curves/s = **{ip['C_b1']:.2f}×**; "
        f"batch 128 {ip['onnx_1t_b128']:.0f} vs {ip['torch_1t_b128']:.0f} = **{ip['C_b128']:.2f}×**.",
    ]
