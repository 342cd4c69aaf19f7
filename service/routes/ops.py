"""Operations: liveness, readiness, the model's metadata, Prometheus metrics."""

from __future__ import annotations

import sys
from typing import Any

from fastapi import APIRouter, Request
from fastapi.responses import JSONResponse, Response
from starlette.exceptions import HTTPException

from curve_vae import __version__
from curve_vae.inference.model.cpus import blas_threads
from curve_vae.inference.runtime import CurveRuntime
from curve_vae.service import responses as r
from curve_vae.service.api_docs import curl_sample, error_docs
from curve_vae.service.deps import RuntimeDep, SettingsDep, coalescer_of
from curve_vae.service.settings import Settings

ops_router = APIRouter(tags=["operations"])


#: What /health and /ready say while the model warms up.
WARMING_UP = (
    "warming up: the reading's compiled kernels load from numba's cache, or compile into it on a first start "
    "(15-30 s); requests sent now wait for it"
)


@ops_router.get(
    "/health",
    response_model=r.StatusResponse,
    response_model_exclude_none=True,
    responses=error_docs(503),
    summary="Liveness",
    openapi_extra=curl_sample("/health"),
)
async def health(request: Request) -> Any:
    """200 while the process serves requests: "ok", or "warming up" while the model warms up (a page asks here, where
    a 200 logs nothing in a browser's console); 503 where the model's warm-up failed (the process cannot serve it:
    restart it)."""
    state = request.app.state
    if state.failed:
        return _status(503, "failed", f"the model cannot serve: {state.failed}")
    if state.warming is not None and not state.warming.done():
        return r.StatusResponse(status="warming up", detail=WARMING_UP)
    return r.StatusResponse(status="ok")


@ops_router.get(
    "/ready",
    response_model=r.StatusResponse,
    response_model_exclude_none=True,
    responses={503: {"description": "Warming up, failed or stopping", "model": r.StatusResponse}},
    summary="Readiness",
    openapi_extra=curl_sample("/ready"),
)
async def ready(request: Request) -> Any:
    """200 once the model is loaded and warm; 503 before that (status "warming up"), where its warm-up failed
    ("failed") and while shutting down ("stopping"), with `detail` saying which."""
    state = request.app.state
    if state.failed:
        return _status(503, "failed", f"the model cannot serve: {state.failed}")
    if state.warming is not None and not state.warming.done():
        return _status(503, "warming up", WARMING_UP)
    if not state.ready or state.runtime is None:
        return _status(503, "stopping", "the model is not loaded")
    return r.StatusResponse(status="ready")


def _status(code: int, status: str, detail: str) -> JSONResponse:
    return JSONResponse(r.StatusResponse(status=status, detail=detail).model_dump(), status_code=code)


@ops_router.get(
    "/model",
    response_model=r.ModelInfo,
    responses=error_docs(503),
    summary="The model being served",
    openapi_extra=curl_sample("/model"),
)
async def model_info(request: Request, runtime: RuntimeDep, settings: SettingsDep) -> r.ModelInfo:
    """Name, version, dimensions and checksums from the manifest, and the providers the sessions actually use."""
    m = runtime.manifest
    present = runtime.model_dir
    return r.ModelInfo(
        name=m.name,
        version=m.version,
        service_version=__version__,
        created=m.created,
        variant=m.variant,
        n_points=runtime.n_points,
        latent_dim=runtime.latent_dim,
        model_size=runtime.model_size,
        reading=default_reading(runtime),
        ranker=m.ranker.model_dump(include={"file", "kind", "held_out"}) if m.ranker else None,
        spacer=m.spacer.model_dump(include={"file", "kind", "held_out"}) if m.spacer else None,
        prior=m.prior.model_dump(include={"kind", "components", "fitted_on"}) if m.prior else None,
        priors={name: p.describe() for name, p in runtime.priors.items()},
        spline=(
            {"n_ctrl": m.spline.n_ctrl, "degree": m.spline.degree, "knots": runtime.graphs.knots.tolist()}
            | {
                "learned_params": runtime.graphs.has_params,
                "placement": "closest" if runtime.closest_placement else "index",
            }
            if m.spline is not None and runtime.graphs.knots is not None
            else None
        ),
        # the files this model directory holds (an installed package ships no vae.pt: serving never reads it)
        files={k: r.FileInfo(sha256=v.sha256, bytes=v.bytes) for k, v in m.files.items() if (present / k).is_file()},
        cache=runtime.cache.stats() if runtime.cache is not None else None,
        providers=runtime.graphs.providers,
        requested_providers=runtime.graphs.requested_providers,
        onnxruntime=runtime.graphs.onnxruntime_version,
        metrics=m.metrics,
        limits={
            "max_curves": settings.max_curves,
            "max_points": settings.max_points,
            "max_body_bytes": settings.max_body_bytes,
            "max_stream_curves": settings.max_stream_curves,
            "max_mesh_triangles": settings.max_mesh_triangles,
            "max_refine_work": settings.max_refine_work,
        },
        execution=execution_of(request, runtime),
    )


def default_reading(runtime: Any) -> dict[str, str | int]:
    """The reading a request gets when it sets no reading field, "auto" made concrete."""
    r = runtime.reading()
    return {"pose": r.pose, "spacing": r.spacing, "looks": r.looks, "refine": r.refine}


@ops_router.get(
    "/metrics",
    summary="Prometheus metrics",
    response_class=Response,
    openapi_extra=curl_sample("/metrics"),
    responses={
        200: {
            "content": {
                "text/plain": {
                    "example": 'curve_vae_http_requests_total{method="POST",route="/encode",status="200"} 3.0\n'
                }
            },
            "description": "Prometheus text exposition format.",
        }
    },
)
async def metrics(request: Request) -> Response:
    """Request counts by route and status, request and inference latency histograms, batch sizes."""
    if not request.app.state.settings.metrics:
        raise HTTPException(404, "metrics are off on this server (CURVE_VAE_METRICS=false)")
    metrics = request.app.state.metrics
    metrics.mirror(request.app.state.runtime)
    body, content_type = metrics.render()
    return Response(body, media_type=content_type)


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
