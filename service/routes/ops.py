"""Operations: liveness, readiness, the model's metadata, Prometheus metrics."""

from __future__ import annotations

from typing import Any

import onnxruntime as ort
from fastapi import APIRouter, Request
from fastapi.responses import Response
from starlette.exceptions import HTTPException

from curve_vae import __version__
from curve_vae.service import schemas as s
from curve_vae.service.api_docs import curl_sample, error_docs
from curve_vae.service.deps import (
    RuntimeDep,
    SettingsDep,
    execution_of,
    runtime_of,
)

ops_router = APIRouter(tags=["operations"])


@ops_router.get("/health", response_model=s.StatusResponse, summary="Liveness", openapi_extra=curl_sample("/health"))
async def health() -> dict[str, str]:
    """200 while the process serves requests, model loaded or not."""
    return {"status": "ok"}


@ops_router.get(
    "/ready",
    response_model=s.StatusResponse,
    responses=error_docs(503),
    summary="Readiness",
    openapi_extra=curl_sample("/ready"),
)
async def ready(request: Request) -> dict[str, str]:
    """200 once the model is loaded and a warm-up inference succeeded; 503 before that and while shutting down."""
    runtime_of(request)
    return {"status": "ready"}


@ops_router.get(
    "/model",
    response_model=s.ModelInfo,
    responses=error_docs(503),
    summary="The model being served",
    openapi_extra=curl_sample("/model"),
)
async def model_info(request: Request, runtime: RuntimeDep, settings: SettingsDep) -> dict[str, Any]:
    """Name, version, dimensions and checksums from the manifest, and the providers the sessions actually use."""
    m = runtime.manifest
    return {
        "name": m.get("name", "curve-vae"),
        "version": str(m.get("version", "")),
        "service_version": __version__,
        "created": m.get("created"),
        "variant": m.get("variant"),
        "n_points": runtime.n_points,
        "latent_dim": runtime.latent_dim,
        "model_size": runtime.model_size,
        "prior": (
            {k: v for k, v in m["prior"].items() if k in ("kind", "components", "fitted_on")}
            if m.get("prior")
            else None
        ),
        "spline": (
            {"n_ctrl": m["spline"]["n_ctrl"], "degree": m["spline"]["degree"], "knots": m["spline"]["knots"]}
            | {"learned_params": runtime.has_params, "placement": "closest" if runtime.closest_placement else "index"}
            if m.get("spline")
            else None
        ),
        "files": {k: {"sha256": v["sha256"], "bytes": v.get("bytes", 0)} for k, v in m["files"].items()},
        "providers": runtime.providers,
        "requested_providers": runtime.requested_providers,
        "onnxruntime": ort.__version__,
        "metrics": m.get("metrics"),
        "limits": {
            "max_curves": settings.max_curves,
            "max_points": settings.max_points,
            "max_body_bytes": settings.max_body_bytes,
            "max_stream_curves": settings.max_stream_curves,
            "max_mesh_triangles": settings.max_mesh_triangles,
            "max_refine_work": settings.max_refine_work,
        },
        "execution": execution_of(request, runtime),
    }


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
    body, content_type = request.app.state.metrics.render()
    return Response(body, media_type=content_type)
