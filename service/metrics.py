"""Prometheus metrics of one app: request counts by route and status, latencies, batch sizes.

Each app owns a CollectorRegistry, so several apps in one process (tests) never share or collide. With
`--workers N` the server gives the workers one PROMETHEUS_MULTIPROC_DIR (service.server), prometheus-client keeps
every worker's values in files there, and whichever worker a scrape reaches answers for all of them: counts and
histograms summed, the gauges summed over the live workers (`curve_vae_ready`: their least, so 1 only when every
worker is ready). The gauges that mirror the runtime (graph rows, the cache) are set after every inference, so a
worker that is not scraped still reports its own.
"""

from __future__ import annotations

import os
import time
from collections.abc import Iterable
from typing import Any

from prometheus_client import (
    CONTENT_TYPE_LATEST,
    CollectorRegistry,
    Counter,
    Gauge,
    Histogram,
    generate_latest,
    multiprocess,
)
from starlette.types import ASGIApp, Message, Receive, Scope, Send

#: Where prometheus-client keeps the workers' values; set in the environment, it is on for the whole process.
MULTIPROC_DIR = "PROMETHEUS_MULTIPROC_DIR"


def multiprocess_mode() -> bool:
    """Whether this process writes its metrics for a scrape of any worker to collect (`--workers` N > 1)."""
    return bool(os.environ.get(MULTIPROC_DIR))


LATENCY_BUCKETS = (0.001, 0.0025, 0.005, 0.01, 0.025, 0.05, 0.1, 0.25, 0.5, 1.0, 2.5, 5.0, 10.0)
BATCH_BUCKETS = (1, 2, 4, 8, 16, 32, 64, 128, 256, 512, 1024, 4096)
COALESCED_BUCKETS = (1, 2, 3, 4, 6, 8, 12, 16, 24, 32)
UNMATCHED = "unmatched"  # route label of paths no route serves, so scanners cannot blow up the label set


class Metrics:
    """The app's collectors; `render()` gives the Prometheus text exposition."""

    def __init__(self) -> None:
        self.registry = CollectorRegistry()
        self._http()
        self._inference()
        self._runtime_gauges()

    def _http(self) -> None:
        self.requests = Counter(
            "curve_vae_http_requests",
            "HTTP requests answered, by route template and status.",
            ["method", "route", "status"],
            registry=self.registry,
        )
        self.latency = Histogram(
            "curve_vae_http_request_duration_seconds",
            "Time from request to the end of the response.",
            ["method", "route"],
            buckets=LATENCY_BUCKETS,
            registry=self.registry,
        )

    def _inference(self) -> None:
        self.batch_size = Histogram(
            "curve_vae_batch_size",
            "Curves (or latents) in each inference request; for /interpolate, curves returned.",
            ["route"],
            buckets=BATCH_BUCKETS,
            registry=self.registry,
        )
        self.inference = Histogram(
            "curve_vae_inference_duration_seconds",
            "Time in the worker thread: pre-processing, ONNX runs, post-processing and JSON rendering.",
            ["route"],
            buckets=LATENCY_BUCKETS,
            registry=self.registry,
        )
        self.coalesced = Histogram(
            "curve_vae_coalesced_requests",
            "Requests (/encode, /reconstruct) read together in each batch (CURVE_VAE_COALESCE_CURVES).",
            buckets=COALESCED_BUCKETS,
            registry=self.registry,
        )
        self.cancelled = Counter(
            "curve_vae_inference_cancelled",
            "Requests whose inference stopped early: the client disconnected or the request timed out.",
            ["route"],
            registry=self.registry,
        )

    def _runtime_gauges(self) -> None:
        total: Any = {"registry": self.registry, "multiprocess_mode": "livesum"}  # over the live workers
        self.graph_rows = Gauge(
            "curve_vae_graph_rows",
            "Rows (curves or latents) each ONNX graph has run since the start: what the requests cost.",
            ["graph"],
            **total,
        )
        self.cache_hits = Gauge("curve_vae_cache_hits", "Curves read from the encoding cache.", **total)
        self.cache_misses = Gauge("curve_vae_cache_misses", "Curves read afresh.", **total)
        self.cache_bytes = Gauge("curve_vae_cache_bytes", "Bytes the encoding cache holds.", **total)
        self.ready = Gauge(
            "curve_vae_ready",
            "1 once the model is loaded and warmed up (every worker's).",
            registry=self.registry,
            multiprocess_mode="livemin",
        )

    def mirror(self, runtime: Any) -> None:
        """Set the gauges that mirror the runtime: each graph's rows run, the encoding cache's hits, misses, bytes."""
        if runtime is None:
            return
        for graph, rows in runtime.graphs.rows.items():
            self.graph_rows.labels(graph).set(rows)
        if runtime.cache is not None:
            stats = runtime.cache.stats()
            self.cache_hits.set(stats["hits"])
            self.cache_misses.set(stats["misses"])
            self.cache_bytes.set(stats["bytes"])

    def render(self) -> tuple[bytes, str]:
        """The Prometheus text: this app's registry, or with workers, every worker's values."""
        if not multiprocess_mode():
            return generate_latest(self.registry), CONTENT_TYPE_LATEST
        everyone = CollectorRegistry()
        multiprocess.MultiProcessCollector(everyone)
        return generate_latest(everyone), CONTENT_TYPE_LATEST

    @staticmethod
    def worker_exit() -> None:
        """A worker stopping: its live gauges leave the sums (its counts stay in the totals)."""
        if multiprocess_mode():
            multiprocess.mark_process_dead(os.getpid())


class MetricsMiddleware:
    """Counts and times every HTTP request, 413s and 404s included (pure ASGI, so streaming stays intact)."""

    def __init__(self, app: ASGIApp, *, metrics: Metrics, known_paths: Iterable[str]) -> None:
        self.app, self.metrics = app, metrics
        self.known_paths = frozenset(known_paths)

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] != "http":
            await self.app(scope, receive, send)
            return
        start = time.perf_counter()
        status = 500  # what the client gets if the app raises before answering

        async def send_wrapper(message: Message) -> None:
            nonlocal status
            if message["type"] == "http.response.start":
                status = message["status"]
            await send(message)

        try:
            await self.app(scope, receive, send_wrapper)
        finally:
            # The matched route's template; a request stopped before routing (413) is labelled by its path.
            path = getattr(scope.get("route"), "path", None) or scope["path"]
            label = path if path in self.known_paths else UNMATCHED
            method = scope["method"]
            self.metrics.requests.labels(method, label, str(status)).inc()
            self.metrics.latency.labels(method, label).observe(time.perf_counter() - start)
