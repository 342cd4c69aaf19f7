"""Where a graph's time goes, node by node: onnxruntime's own profile of `--runs` runs of each of a model's graphs
(encoder.onnx, decoder.onnx, and where shipped ranker.onnx, spacer.onnx) at `--batch` rows on one intra-op thread,
its heaviest nodes with their shapes, and the rate its convolutions and matrix products reach (multiply-adds × 2 a
second), against which a faster CPU kernel would have to win; then the rows each graph runs a curve for a default
request (`--curves` of the benchmark's paper curves) and what its graphs alone cost a curve at those rows' costs, as
a multiple of one encoder and one decoder row (the serving benchmark's ceiling is one of each a curve).

    .venv/bin/python -m bench.graph_ops                    # batch 8, the single-curve requests a worker coalesces
    .venv/bin/python -m bench.graph_ops --batch 128 --top 5
"""

from __future__ import annotations

import argparse
import collections
import json
import math
import tempfile
from pathlib import Path

import numpy as np
import onnxruntime as ort

ROOT = Path(__file__).resolve().parents[1]
GRAPHS = ("encoder", "decoder", "ranker", "spacer")


def profile(path: Path, batch: int, runs: int) -> dict:
    """Per node: microseconds a run, op, input and output shapes, its weights' shape (onnxruntime's profile leaves
    out the prepacked weights of a transposed convolution); and the run's total."""
    import onnx

    graph = onnx.load(str(path)).graph
    weights = {i.name: list(i.dims) for i in graph.initializer}
    weight_of = {n.name: weights.get(n.input[1]) for n in graph.node if len(n.input) > 1}
    opts = ort.SessionOptions()
    opts.intra_op_num_threads, opts.inter_op_num_threads = 1, 1
    opts.enable_profiling = True
    with tempfile.TemporaryDirectory() as tmp:
        opts.profile_file_prefix = str(Path(tmp) / "graph")
        session = ort.InferenceSession(str(path), opts, providers=["CPUExecutionProvider"])
        (inp,) = session.get_inputs()
        shape = [batch if not isinstance(d, int) else d for d in inp.shape]
        x = np.random.default_rng(0).normal(size=shape).astype(np.float32)
        for _ in range(runs):
            session.run(None, {inp.name: x})
        events = json.loads(Path(session.end_profiling()).read_text())
    nodes: dict[str, dict] = collections.defaultdict(lambda: {"us": 0.0})
    for e in events:
        if e.get("cat") == "Node" and e["name"].endswith("_kernel_time"):
            node = nodes[node_name(e["name"])]
            node["us"] += e["dur"] / runs
            node["op"] = e["args"].get("op_name", "?")
            node["inputs"] = [next(iter(t.values())) for t in e["args"].get("input_type_shape", [])]
            node["outputs"] = [next(iter(t.values())) for t in e["args"].get("output_type_shape", [])]
            node["weights"] = weight_of.get(node_name(e["name"]))
    return {"nodes": dict(nodes), "us": sum(n["us"] for n in nodes.values())}


def node_name(event: str) -> str:
    """The graph's node name of a profile event's ("fused " and "_kernel_time" taken off)."""
    return event.removesuffix("_kernel_time").removeprefix("fused ")


def flops(node: dict) -> float:
    """Multiply-adds × 2 of a convolution (1-D or 2-D, groups ignored), a transposed one (each input value spread
    over its output channels' kernels) or a matrix product; 0 for anything else."""
    ins, outs, w = node.get("inputs", []), node.get("outputs", []), node.get("weights")
    if node["op"] in ("Conv", "FusedConv") and w and outs:
        return 2.0 * math.prod(outs[0]) * math.prod(w[1:])
    if node["op"] == "ConvTranspose" and w and ins:
        return 2.0 * math.prod(ins[0]) * math.prod(w[1:])
    if node["op"] in ("Gemm", "MatMul", "FusedMatMul") and len(ins) >= 2 and outs:
        return 2.0 * math.prod(outs[0]) * ins[0][-1]
    return 0.0


def rows_a_curve(model_dir: Path, curves: int) -> dict[str, float]:
    """Rows each graph runs a curve for a default request of `curves` of the benchmark's paper curves as a caller
    posts them (bench.ceiling), counted at onnxruntime's door: every session's runs, by the file it opened."""
    from bench import ceiling
    from curve_vae.inference.runtime import CurveRuntime

    counted: collections.Counter[str] = collections.Counter()
    run = ort.InferenceSession.run

    def counting(self: ort.InferenceSession, output_names: object, feed: dict, *rest: object) -> object:
        counted[Path(str(self._model_path)).stem] += len(next(iter(feed.values())))
        return run(self, output_names, feed, *rest)  # type: ignore[arg-type]

    rt = CurveRuntime.load(model_dir, providers="cpu", intra_op_threads=1, cache_bytes=0)
    asked = list(ceiling.posted(curves, seed=2))
    ort.InferenceSession.run = counting  # type: ignore[method-assign]
    try:
        rt.reconstruct(asked)
    finally:
        ort.InferenceSession.run = run  # type: ignore[method-assign]
    return {name: n / curves for name, n in counted.items()}


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--model-dir", type=Path, default=ROOT / "models")
    p.add_argument("--batch", type=int, default=8, help="rows a run (default: 8)")
    p.add_argument("--runs", type=int, default=100)
    p.add_argument("--top", type=int, default=4, help="heaviest nodes shown a graph (default: 4)")
    p.add_argument("--curves", type=int, default=128, help="curves of the default request counted (default: 128)")
    a = p.parse_args()
    print(f"onnxruntime {ort.__version__}, one intra-op thread, batch {a.batch}\n")
    print("| graph | ms a run | ms a row | share of its time in convolutions and matrix products | their rate |")
    print("|---|---|---|---|---|")
    heaviest, per_row = [], {}
    for name in GRAPHS:
        path = a.model_dir / f"{name}.onnx"
        if not path.exists():
            continue
        r = profile(path, a.batch, a.runs)
        dense = [n for n in r["nodes"].values() if flops(n) > 0]
        us = sum(n["us"] for n in dense)
        rate = sum(flops(n) for n in dense) / (us * 1e-6) / 1e9 if us else 0.0
        ms = r["us"] / 1e3
        per_row[name] = ms / a.batch
        print(f"| {name} | {ms:.3f} | {ms / a.batch:.3f} | {us / r['us']:.0%} | {rate:.0f} GFLOP/s |")
        for key, n in sorted(r["nodes"].items(), key=lambda kv: -kv[1]["us"])[: a.top]:
            shapes = f"{n['inputs'][:1]} × {n['weights']} → {n['outputs'][:1]}"
            heaviest.append(f"- {name} {key} ({n['op']} {shapes}): {n['us'] / r['us']:.0%}")
    print("\nThe heaviest nodes, share of their graph's time:\n" + "\n".join(heaviest))
    rows = rows_a_curve(a.model_dir, a.curves)
    unit = per_row["encoder"] + per_row["decoder"]
    cost = sum(rows.get(name, 0.0) * per_row[name] for name in per_row)
    counts = ", ".join(f"{name} {rows.get(name, 0.0):.1f}" for name in per_row)
    print(
        f"\nA default request of {a.curves} paper curves runs, a curve: {counts} rows; at the rows' costs above, "
        f"{cost:.2f} ms of graphs a curve, {cost / unit:.2f}× one encoder and one decoder row ({unit:.2f} ms)."
    )


if __name__ == "__main__":
    main()
