"""The REST service: `create_app(settings)` builds a FastAPI app serving the VAE (v1 contract, docs/ARCHITECTURE.md).

This module holds the lifespan (the model is loaded once per worker process, never at import
time) and the app factory; the rest lives by concern:

    routes/curves.py   encode, decode, reconstruct, interpolate, sample, augment (the model)
    routes/design.py   fit, revolve (geometry, no model)
    routes/ops.py      health, ready, model, metrics
    routes/oip.py      the Open Inference Protocol (KServe v2) under /v2: raw tensors, as Triton serves them
    deps.py            settings and runtime from app.state, limits, the bounded run in a worker thread
    errors.py          the one error body and its handlers
    middleware.py      the body size limit;  access.py: API keys;  metrics.py: Prometheus
    api_docs.py        error examples, curl samples and request examples of the OpenAPI page
    web.py             the page at / and the offline docs

Routes are thin: the schema validates, `deps.check_*` applies the limits that depend on the
settings or the model, the `CurveRuntime` on `app.state` computes in a worker thread, and the
route shapes the JSON. Every rejected request gets the same JSON error body:
`{"detail": "curves[2][17][1]: not a finite number", "errors": [{"loc": ..., "msg": ...}]}`.
"""

from __future__ import annotations

import asyncio
import logging
import sys
import time
from collections.abc import AsyncIterator, Callable
from concurrent.futures import ThreadPoolExecutor
from contextlib import asynccontextmanager
from functools import partial
from typing import Any

import anyio
from fastapi import FastAPI
from fastapi.exceptions import RequestValidationError
from starlette.exceptions import HTTPException

from curve_vae.inference.errors import InputError
from curve_vae.inference.model.batching import GraphBatcher
from curve_vae.inference.model.batching import attach as attach_batcher
from curve_vae.inference.model.cpus import (
    available_cpus,
    coalescing_readers,
    inference_slots,
    limit_blas_threads,
    session_config,
    worker_count,
)
from curve_vae.inference.model.manifest import ModelLoadError
from curve_vae.inference.model.opening import compiled_kernels
from curve_vae.inference.runtime import CurveRuntime
from curve_vae.service.deps import runtime_coalescer
from curve_vae.service.errors import on_http_error, on_input_error, on_validation_error
from curve_vae.service.limits import name_priors, state_bounds
from curve_vae.service.metrics import Metrics, MetricsMiddleware
from curve_vae.service.middleware import ApiKeyMiddleware, BodyLimitMiddleware, add_cors
from curve_vae.service.oip import DEFAULT_SIGNATURES, signatures
from curve_vae.service.oip_docs import describe
from curve_vae.service.routes.curves import curves_router
from curve_vae.service.routes.design import design_router
from curve_vae.service.routes.generate import generate_router
from curve_vae.service.routes.oip import oip_router
from curve_vae.service.routes.ops import ops_router
from curve_vae.service.settings import Settings, get_settings
from curve_vae.service.web import mount_web

log = logging.getLogger("service")


@asynccontextmanager
async def _lifespan(app: FastAPI) -> AsyncIterator[None]:
    """Open the model (unless the app was given one) and serve at once: the warm-up — the compiled kernels loaded, or
    compiled on a first start — runs in the background (`_warm_then_serve`), /ready answering 503 "warming up" until it
    is done and requests waiting for it; then the micro-batcher where asked, and everything undone at the end."""
    settings: Settings = app.state.settings
    owned = app.state.runtime is None
    switch = sys.getswitchinterval()
    sys.setswitchinterval(settings.gil_switch_ms / 1e3)  # the event loop's turn comes sooner (Settings)
    app.state.failed = None
    if owned:
        app.state.runtime = await _load_runtime(settings, app.state.slots)
        app.state.warming = asyncio.create_task(_warm_then_serve(app))
    else:  # given loaded and warm
        _serve(app)
    try:
        yield
    finally:
        if app.state.warming is not None:
            app.state.warming.cancel()
            app.state.warming = None
        app.state.ready = False
        app.state.metrics.ready.set(0)
        sys.setswitchinterval(switch)  # the process's own again, for an app that starts again or shares it
        app.state.executor.shutdown(wait=False, cancel_futures=True)
        app.state.executor = inference_executor(app.state.slots)  # for a lifespan that starts again (tests)
        if app.state.batcher is not None:
            app.state.batcher.close()
            app.state.batcher = None
        if owned:
            app.state.runtime = None
        app.state.metrics.worker_exit()


async def _warm_then_serve(app: FastAPI) -> None:
    """The warm-up of a just-opened model in a worker thread (CurveRuntime.warm_up), said in the log — what it loads
    or compiles, and when it is ready — then `_serve`. A warm-up that fails is logged and stated by /health and
    /ready (503), so an orchestrator restarts the process."""
    runtime: CurveRuntime = app.state.runtime
    where, missing = compiled_kernels()
    if missing:
        log.info("warming up: compiling the reading's kernels into %s (a first start only; 15-30 s)", where)
    else:
        log.info("warming up: loading the reading's compiled kernels from %s", where)
    start = time.perf_counter()
    try:
        await anyio.to_thread.run_sync(runtime.warm_up)
    except ModelLoadError as e:
        app.state.failed = str(e)
        log.error("cannot serve the model: %s", e)
        return
    _serve(app)
    log.info("ready after %.1f s of warming up", time.perf_counter() - start)


def _serve(app: FastAPI) -> None:
    """A warm runtime served: the micro-batcher where asked, the coalescer, and ready."""
    settings: Settings = app.state.settings
    runtime: CurveRuntime = app.state.runtime
    app.state.batcher = _start_batcher(app, settings, runtime) if settings.micro_batch else None
    app.state.coalescer = (
        runtime_coalescer(
            runtime,
            max_curves=settings.coalesce_curves,
            readers=coalescing_readers(settings),
            observe=lambda jobs, _curves: app.state.metrics.coalesced.observe(jobs),
        )
        if settings.coalesce_curves
        else None
    )
    app.state.ready = True
    app.state.metrics.ready.set(1)
    log.info(
        "serving %s %s from %s on %s",
        runtime.manifest.name,
        runtime.manifest.version,
        settings.model_dir,
        runtime.graphs.providers,
    )


async def _load_runtime(settings: Settings, slots: int) -> CurveRuntime:
    """The model of `settings`, loaded in a worker thread with the sessions the CPUs allow (logged, with why)."""
    config = session_config(settings)
    log.info(
        "onnxruntime: %d session pairs of %d threads (%s), %d inferences at once (%s), spinning %s",
        config.sessions,
        config.intra_op_threads,
        "CURVE_VAE_INTRA_OP_THREADS" if settings.intra_op_threads else f"{available_cpus()} CPUs shared out",
        slots,
        "CURVE_VAE_INFERENCE_CONCURRENCY" if settings.inference_concurrency else f"{worker_count(settings)} workers",
        "on" if config.spinning else "off",
    )
    try:
        runtime = await anyio.to_thread.run_sync(
            partial(
                CurveRuntime.load,
                settings.model_dir,
                providers=settings.providers,
                batch_size=settings.batch_size,
                sessions=config,
                placement=settings.placement,
                cache_bytes=settings.cache_bytes,
                priors_dir=settings.priors_dir,
                warm_up=False,  # _warm_then_serve, while the server answers
            )
        )
    except ModelLoadError as e:
        log.error("cannot serve the model: %s", e)
        raise
    # numpy's and scipy's BLAS get one inference's threads too (inference/model/cpus.py), now that both are loaded
    log.info("BLAS: %d threads an inference", limit_blas_threads(config.intra_op_threads))
    return runtime


def _start_batcher(app: FastAPI, settings: Settings, runtime: CurveRuntime) -> GraphBatcher:
    """The micro-batcher over the runtime's sessions, and inference threads whose graph runs go through it."""
    batcher = GraphBatcher(
        runtime.graphs.pool,
        {
            "encoder": runtime.graphs.encoder.get_inputs()[0].name,
            "decoder": runtime.graphs.decoder.get_inputs()[0].name,
        },
        max_rows=settings.micro_batch_rows,
        max_wait=settings.micro_batch_wait_ms / 1e3,
        runners=app.state.slots,
        registry=app.state.metrics.registry,
    )
    app.state.executor.shutdown(wait=False)
    # Threads enough for a full batch of single-curve requests to wait together; runs are bounded by the slots.
    app.state.executor = inference_executor(app.state.slots + settings.micro_batch_rows, batcher)
    return batcher


def inference_executor(threads: int, batcher: GraphBatcher | None = None) -> ThreadPoolExecutor:
    """The inference threads: the app's own pool, one thread per slot (not anyio's default pool of 40, shared with
    every sync call of the app, which let more inferences run at once than the CPUs hold); with micro-batching,
    threads whose graph runs go through the batcher."""
    return ThreadPoolExecutor(
        max_workers=threads, thread_name_prefix="inference", initializer=attach_batcher, initargs=(batcher,)
    )


DESCRIPTION = """\
An Inception VAE for 2D curves (Barzegar Khalilsaraei & Augsdörfer, WSCG 2025) behind REST.

A curve is a JSON array of `[x, y]` points: any frame, any order of magnitude, any length ≥ 4.
Every endpoint takes a batch. With `frame: "auto"` (the default) each curve is shifted and
uniformly scaled into the model's frame and results are mapped back. Curves of any length are
resampled to the model's 161 points (`spacing`: along their own order, as given, or by
arc length) and come back at their own length, or `n_points`. Errors are JSON:
`detail` names the field, curve and point.
"""


OPENAPI_TAGS = [
    {"name": "curves", "description": "Encode, decode, reconstruct, interpolate, sample and augment curves."},
    {"name": "design", "description": "B-spline fits and surfaces of revolution: geometry, no model needed."},
    {"name": "operations", "description": "Health, readiness, model metadata and metrics."},
    {
        "name": "open inference protocol",
        "description": "The Open Inference Protocol (KServe v2), as NVIDIA Triton and KServe speak it: the "
        "same client code calls this server or Triton serving `curve-vae triton`'s export. Raw model-plane "
        'tensors (no frames, no resampling); errors are `{"error": "..."}`.',
    },
]


def create_app(settings: Settings | None = None, *, runtime: CurveRuntime | None = None) -> FastAPI:
    """The app for `settings` (default: the environment). Pass a loaded `runtime` to share one between apps."""
    from curve_vae import __version__

    settings = settings or get_settings()
    app = FastAPI(
        title="curve-vae",
        version=__version__,
        description=DESCRIPTION,
        lifespan=_lifespan,
        docs_url=None,  # served offline by service.web
        redoc_url=None,
        generate_unique_id_function=lambda route: route.name,  # operationId "encode", not "encode_encode_post"
        openapi_tags=OPENAPI_TAGS,
    )
    app.state.settings, app.state.runtime, app.state.ready = settings, runtime, False
    app.state.warming = None  # the lifespan's warm-up task while it runs
    app.state.failed = None  # why the warm-up failed, where it did
    app.state.batcher = None
    app.state.metrics = Metrics()
    app.state.coalescer = None  # the lifespan's, over the runtime
    app.state.pending = 0  # requests in deps.run_inference: running or waiting for an inference slot
    app.state.slots = inference_slots(settings)
    app.state.executor = inference_executor(app.state.slots)
    app.include_router(curves_router)
    app.include_router(generate_router)
    app.include_router(design_router)
    app.include_router(ops_router)
    app.include_router(oip_router)
    mount_web(app)
    app.add_exception_handler(RequestValidationError, on_validation_error)
    app.add_exception_handler(InputError, on_input_error)
    app.add_exception_handler(HTTPException, on_http_error)
    _add_request_middleware(app, settings)
    app.openapi = _openapi_of(app, settings)  # type: ignore[method-assign]  # FastAPI's documented override
    routes = (
        *curves_router.routes,
        *generate_router.routes,
        *design_router.routes,
        *ops_router.routes,
        *oip_router.routes,
        *app.routes,
    )
    paths = [r.path for r in routes if hasattr(r, "path")]
    app.add_middleware(MetricsMiddleware, metrics=app.state.metrics, known_paths=paths)  # last: outermost
    return app


def _add_request_middleware(app: FastAPI, settings: Settings) -> None:
    """The body limit, API keys and CORS. Each middleware added wraps those added before it: CORS headers reach
    the body limit's 413s too, and the metrics, added after these, see everything."""
    app.add_middleware(BodyLimitMiddleware, max_body_bytes=settings.max_body_bytes)
    if settings.api_keys:  # outside the body limit: a request without a key is refused before its body is read
        app.add_middleware(ApiKeyMiddleware, keys=settings.api_keys)
    add_cors(app, settings)


def _openapi_of(app: FastAPI, settings: Settings) -> Callable[[], dict[str, Any]]:
    """The app's `openapi`: FastAPI's schema, with the bounds of these settings and of the loaded model stated in it
    (built again when the loaded model's latent size changes)."""

    def runtime_dim() -> int | None:
        rt = app.state.runtime
        return rt.latent_dim if rt is not None else None

    def openapi() -> dict[str, Any]:
        if app.openapi_schema is None or getattr(app.state, "openapi_for", None) != runtime_dim():
            app.openapi_schema = None
            app.state.openapi_for = runtime_dim()
            schema = state_bounds(FastAPI.openapi(app), settings, runtime_dim())
            rt = app.state.runtime
            if rt is not None:
                name_priors(schema, rt.sampler.names)
            app.openapi_schema = describe(
                schema, signatures(rt) if rt is not None else DEFAULT_SIGNATURES, settings.max_curves
            )
        return app.openapi_schema

    return openapi


def create_app_from_env() -> FastAPI:
    """uvicorn factory for worker processes: settings from CURVE_VAE_* variables."""
    return create_app(Settings())
