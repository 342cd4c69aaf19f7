"""Micro-batching (off by default on CPU): concurrent requests' graph runs gathered into one onnxruntime run.

Like Triton's dynamic batcher: the first run request waits at most `max_wait` seconds for others of the same
graph, up to `max_rows` rows; the batch runs once on a session pair of its own, and each caller gets its own
rows back. Requests still do their pre- and post-processing (frames, resampling, JSON) on the inference
threads; only `CurveRuntime`'s graph runs go through here, so every route and option batches alike.

- A failing batch is run again item by item, so a bad item fails only its own request.
- A client that disconnects leaves its item in the batch; its rows are computed and dropped, nobody else waits.
- Batch sizes (rows per run) and the time items wait in the queue are Prometheus histograms.

Measured on this project's 2-core CPU (docs/BENCHMARKS.md): onnxruntime runs a 1-curve batch as efficiently
per curve as a 128-curve one, so gathering buys little there and the wait costs latency; on a GPU a batch of
many curves costs about what one does.
"""

from __future__ import annotations

import queue
import threading
import time
from collections.abc import Sequence
from concurrent.futures import Future
from dataclasses import dataclass, field

import numpy as np
from prometheus_client import CollectorRegistry, Histogram

from curve_vae.inference.model.sessions import SessionPool

WAIT_BUCKETS = (0.0001, 0.00025, 0.0005, 0.001, 0.002, 0.005, 0.01, 0.025, 0.05, 0.1)
ROW_BUCKETS = (1, 2, 4, 6, 8, 12, 16, 24, 32, 48, 64, 128, 256)
GRAPHS = ("encoder", "decoder")

_local = threading.local()


def current() -> GraphBatcher | None:
    """The batcher of the calling inference thread (set by the app's executor), or None: run directly."""
    return getattr(_local, "batcher", None)


def attach(batcher: GraphBatcher | None) -> None:
    """Make `batcher` the calling thread's (the inference executor's initializer)."""
    _local.batcher = batcher


@dataclass
class _Item:
    x: np.ndarray  # (rows, ...) one caller's input
    outputs: list[str] | None
    future: Future = field(default_factory=Future)
    queued: float = field(default_factory=time.perf_counter)


class GraphBatcher:
    """Gathers concurrent runs of each graph; `run(graph, x, outputs)` blocks its caller until its rows are back."""

    def __init__(
        self,
        pool: SessionPool,
        input_names: dict[str, str],
        *,
        max_rows: int,
        max_wait: float,
        runners: int,
        registry: CollectorRegistry | None = None,
    ) -> None:
        self.pool, self.input_names = pool, input_names
        self.max_rows, self.max_wait = max_rows, max_wait
        self.rows = Histogram(
            "curve_vae_microbatch_rows",
            "Rows (curves or latents) in each micro-batched graph run.",
            ["graph"],
            buckets=ROW_BUCKETS,
            registry=registry,
        )
        self.wait = Histogram(
            "curve_vae_microbatch_queue_seconds",
            "Time a graph run waited to be gathered into a micro-batch and started.",
            ["graph"],
            buckets=WAIT_BUCKETS,
            registry=registry,
        )
        self.queues: dict[str, queue.Queue[_Item | None]] = {g: queue.Queue() for g in GRAPHS}
        self._running = threading.Semaphore(runners)  # at most `runners` graph runs at once, either graph
        self._threads = [
            threading.Thread(target=self._loop, args=(g,), name=f"microbatch-{g}-{i}", daemon=True)
            for g in GRAPHS
            for i in range(runners)
        ]
        for t in self._threads:
            t.start()

    def run(self, graph: str, x: np.ndarray, outputs: list[str] | None = None) -> list[np.ndarray]:
        item = _Item(x, outputs)
        self.queues[graph].put(item)
        return item.future.result()

    def close(self) -> None:
        for q in self.queues.values():
            for _ in range(len(self._threads)):
                q.put(None)

    def _loop(self, graph: str) -> None:
        q = self.queues[graph]
        while True:
            first = q.get()
            if first is None:
                return
            items, rows = [first], len(first.x)
            deadline = first.queued + self.max_wait
            while rows < self.max_rows:
                left = deadline - time.perf_counter()
                try:
                    item = q.get(timeout=left) if left > 0 else q.get_nowait()
                except queue.Empty:
                    break
                if item is None:
                    q.put(None)  # for this thread's next get: stop after this batch
                    break
                items.append(item)
                rows += len(item.x)
            with self._running:
                self._run(graph, items)

    def _run(self, graph: str, items: Sequence[_Item]) -> None:
        started = time.perf_counter()
        for item in items:
            self.wait.labels(graph).observe(started - item.queued)
        session = self.pool.pair()[GRAPHS.index(graph)]
        name = self.input_names[graph]
        outputs = items[0].outputs
        if len(items) > 1 and all(item.outputs == outputs for item in items):
            try:
                batch = np.concatenate([item.x for item in items])
                results = session.run(outputs, {name: batch})
            except Exception:
                pass  # one by one below: a bad item fails only its own caller
            else:
                self.rows.labels(graph).observe(len(batch))
                start = 0
                for item in items:
                    stop = start + len(item.x)
                    item.future.set_result([r[start:stop] for r in results])
                    start = stop
                return
        for item in items:
            self.rows.labels(graph).observe(len(item.x))
            try:
                item.future.set_result(session.run(item.outputs, {name: item.x}))
            except Exception as e:
                item.future.set_exception(e)
