"""What every model route shares: settings and runtime from app.state, the limits that depend on them, and
the bounded, timed run of the work in a worker thread."""

from __future__ import annotations

import asyncio
import sys
import time
from collections.abc import Callable, Hashable
from typing import Annotated, Any, TypeVar

import anyio
import numpy as np
from fastapi import Depends, Request
from fastapi.responses import Response
from starlette.exceptions import HTTPException

from curve_vae.inference.coalescing import Coalescer, Read, read_alone
from curve_vae.inference.cpus import blas_threads
from curve_vae.inference.errors import InputError
from curve_vae.inference.graphs import Cancelled, CancelToken, cancellable
from curve_vae.inference.runtime import CurveRuntime
from curve_vae.service.metrics import Metrics, multiprocess_mode
from curve_vae.service.settings import Settings

T = TypeVar("T")


def settings_of(request: Request) -> Settings:
    return request.app.state.settings


def runtime_of(request: Request) -> CurveRuntime:
    state = request.app.state
    if getattr(state, "failed", None):
        raise HTTPException(503, f"the model cannot serve: {state.failed}")
    if not state.ready or state.runtime is None:
        raise HTTPException(503, "the model is not loaded yet; GET /ready answers 200 once it is")
    return state.runtime


async def _settings(request: Request) -> Settings:
    return settings_of(request)


async def warmed(request: Request) -> None:
    """Returns once the model's warm-up is over: a request that comes while it runs (a page opened at once, a client
    that did not wait for /ready) waits for it (service.app._warm_then_serve)."""
    warming = getattr(request.app.state, "warming", None)  # an app built without the lifespan's state has none
    if warming is not None and not warming.done():
        await asyncio.shield(warming)


async def _runtime(request: Request) -> CurveRuntime:
    await warmed(request)
    return runtime_of(request)


# Async dependencies: FastAPI runs a plain `def` dependency on a worker thread, two thread hops per request for
# what is an attribute read (measured: a fifth of a single-curve request's server CPU).
SettingsDep = Annotated[Settings, Depends(_settings)]
RuntimeDep = Annotated[CurveRuntime, Depends(_runtime)]


def check_output(output: str, runtime: CurveRuntime) -> None:
    """A spline output needs a model with a B-spline head."""
    if output != "points" and not runtime.has_splines:
        raise InputError(
            ("output",),
            f'"{output}" needs a model with a B-spline head, and this one has none (GET /model: spline is null); '
            'ask for "points", or fit splines to the points with /fit',
        )


def execution_of(request: Request, runtime: CurveRuntime) -> dict[str, Any]:
    """What GET /model reports under `execution`: the sessions' applied options and the inference threads."""
    settings: Settings = request.app.state.settings
    batching = (
        {"rows": settings.micro_batch_rows, "wait_ms": settings.micro_batch_wait_ms}
        if getattr(request.app.state, "batcher", None) is not None
        else None
    )
    return {
        **runtime.graphs.pool.applied(),
        "blas_threads": blas_threads(),
        "inference_threads": request.app.state.slots,
        "gil_switch_ms": round(sys.getswitchinterval() * 1e3, 6),
        "micro_batch": batching,
        "coalesce": None
        if (coalescer := coalescer_of(request)) is None
        else {"curves": coalescer.max_curves, "readers": coalescer.readers, "hold_ms": coalescer.hold * 1e3},
    }


async def in_executor(request: Request, fn: Callable[..., T], *args: Any, token: CancelToken | None = None) -> T:
    """`fn(*args)` on one of the app's inference threads (at most one inference per slot at once, first come
    first served), under `token` when given: cancelled, the work stops at its next checkpoint (inference.graphs)."""

    def run() -> T:
        if token is None:
            return fn(*args)
        token.check()  # abandoned while it queued: never starts
        with cancellable(token):
            return fn(*args)

    return await asyncio.wrap_future(request.app.state.executor.submit(run))


#: How often a running request looks whether its client has gone.
DISCONNECT_POLL_S = 0.05


async def _watch_disconnect(request: Request, token: CancelToken) -> None:
    """Cancel `token` once the client has disconnected (polling Starlette's receive channel)."""
    while not token.cancelled:
        if await request.is_disconnected():
            token.cancel("the client disconnected")
            return
        await asyncio.sleep(DISCONNECT_POLL_S)


def coalescer_of(request: Request) -> Coalescer[Read] | None:
    """The app's coalescer of concurrent /encode and /reconstruct requests, None where CURVE_VAE_COALESCE_CURVES=0."""
    return getattr(request.app.state, "coalescer", None)


async def coalesced(
    request: Request, route: str, key: Hashable, curves: list[np.ndarray], render: Callable[[Any], Response]
) -> Response:
    """`run_inference` of a job the app's coalescer may read together with other requests' (inference.coalescing):
    registered before it queues, so requests that queue together are read together; `render` builds the response
    from this request's own part. Without a coalescer, or with more than half a batch of curves (it gains little
    from company, and would hold the coalescer's readers from the small requests), the job is read alone."""
    runtime = runtime_of(request)  # 503 until the model is loaded
    coalescer = coalescer_of(request)
    if coalescer is None or len(curves) > coalescer.max_curves // 2:
        return await run_inference(request, route, len(curves), lambda: render(read_alone(runtime, key, curves)))
    job = coalescer.submit(key, curves)
    try:
        return await run_inference(request, route, len(curves), lambda: render(coalescer.result(job)), token=job.token)
    finally:
        coalescer.forget(job)


async def run_inference(
    request: Request, route: str, batch: int, work: Callable[[], Response], *, token: CancelToken | None = None
) -> Response:
    """Run `work` (inference and JSON rendering) on an inference thread, never on the event loop; timed, and at
    most one per inference slot (CURVE_VAE_INFERENCE_CONCURRENCY) at once.

    Bounded both ways: with `slots + max_queue` requests already in here, a new one is answered 503 with
    Retry-After at once instead of joining an ever longer queue; one that takes longer than `request_timeout`
    seconds (queueing included) is answered 504. Either way, and when the client disconnects, the work is cancelled:
    its thread stops at the next chunk boundary and the slot is free for the next request. `token`: the request's
    own, where its work was registered under it before (a coalesced job's).
    """
    settings: Settings = request.app.state.settings
    state = request.app.state
    if state.pending >= state.slots + settings.max_queue:
        raise HTTPException(
            503,
            f"busy: {state.pending} requests are running or queued ({state.slots} inference slots, "
            f"CURVE_VAE_INFERENCE_CONCURRENCY, + CURVE_VAE_MAX_QUEUE {settings.max_queue}); retry in a moment",
            headers={"Retry-After": "1"},
        )
    metrics: Metrics = state.metrics
    metrics.batch_size.labels(route).observe(batch)
    state.pending += 1
    start = time.perf_counter()
    token = token or CancelToken()
    watcher = asyncio.ensure_future(_watch_disconnect(request, token))
    try:
        with anyio.fail_after(settings.request_timeout or None):
            return await in_executor(request, work, token=token)
    except TimeoutError:
        token.cancel("past CURVE_VAE_REQUEST_TIMEOUT")
        raise HTTPException(
            504, f"the request took longer than {settings.request_timeout:g} s (CURVE_VAE_REQUEST_TIMEOUT); send less"
        ) from None
    except Cancelled:
        metrics.cancelled.labels(route).inc()
        raise HTTPException(499, f"cancelled: {token.reason}") from None
    finally:
        token.cancel("the request ended")  # a still-running thread (a timeout) stops at its next checkpoint
        watcher.cancel()
        state.pending -= 1
        metrics.inference.labels(route).observe(time.perf_counter() - start)
        if multiprocess_mode():  # a scrape may reach another worker: this one's gauges must be current
            metrics.mirror(state.runtime)
