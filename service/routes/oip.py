"""The Open Inference Protocol (KServe v2) under /v2: health, model metadata and readiness, and infer on raw tensors.

A Triton or KServe client (tritonclient.http, kserve's REST client, plain JSON) talks to these
routes as to a Triton server running the repository `curve-vae triton` writes. The tensors are
the graphs' own, in the model's plane: no frames, no resampling, no pose (see service/oip.py and
docs/DEPLOYMENT.md for how the REST routes' geometry wraps them). Errors are the protocol's
`{"error": "..."}`: 400 for a request that does not fit the model's tensors, 404 for a model this
server does not have, 401/413/503/504 as on every other route (service/errors.py speaks the
protocol's format for every path under /v2). Inference runs like every other model route: on an
inference thread, bounded by the same slots and queue (deps.run_inference).
"""

from __future__ import annotations

import json
from collections.abc import Awaitable, Callable
from typing import Any

from fastapi import APIRouter, Request
from fastapi.responses import Response
from pydantic import BaseModel, Field

from curve_vae.service import oip
from curve_vae.service.api_docs import ERROR_EXAMPLES, curl_sample
from curve_vae.service.deps import run_inference, runtime_of
from curve_vae.service.errors import oip_error
from curve_vae.service.oip import OipError
from curve_vae.service.routing import JSON

TAG = "open inference protocol"
oip_router = APIRouter(tags=[TAG])

RAW_TENSORS = (
    "Raw model-plane tensors: no frames, no resampling, no pose. The REST routes do that around these same graphs "
    "(/encode brings any curve into the plane and resamples it to the encoder's points; /decode maps the result "
    "back), so a curve sent here must already be in the model's plane at its point count — what /encode with "
    '`frame: "model"` and exactly that many points sends to the encoder.'
)


class OipErrorResponse(BaseModel):
    error: str = Field(description="What is wrong: the field, the tensor and the expected value.")


class ServerMetadata(BaseModel):
    name: str
    version: str
    extensions: list[str]


class Live(BaseModel):
    live: bool


class Ready(BaseModel):
    ready: bool


class ModelReady(BaseModel):
    name: str
    ready: bool


class TensorMetadata(BaseModel):
    name: str
    datatype: str = Field(description="The protocol's data type: FP32 for every tensor of this model.")
    shape: list[int] = Field(description="-1 for the batch axis.")


class ModelMetadata(BaseModel):
    name: str
    versions: list[str] = Field(description="The model's version (manifest.json): one per server.")
    platform: str
    inputs: list[TensorMetadata]
    outputs: list[TensorMetadata]


class OutputTensor(BaseModel):
    name: str
    shape: list[int]
    datatype: str
    data: list[float] = Field(description="The elements, flattened row-major.")


class InferResponse(BaseModel):
    model_name: str
    model_version: str
    id: str | None = Field(None, description="The request's id, where it gave one.")
    outputs: list[OutputTensor]


OIP_ERRORS = {
    400: (
        "The request does not fit the model's tensors.",
        "inputs[0].shape: [1, 160, 2] does not fit curves's shape [-1, 161, 2] (-1: any size)",
    ),
    404: ("No such model on this server: it serves encoder and decoder.", "unknown model 'resnet'"),
}


def oip_errors(*codes: int) -> dict[int | str, dict[str, Any]]:
    """OpenAPI responses of the protocol's error body, with the service's descriptions where the status is shared."""
    out: dict[int | str, dict[str, Any]] = {}
    for code in codes:
        description, message = OIP_ERRORS[code] if code in OIP_ERRORS else ERROR_EXAMPLES[code][:2]
        out[code] = {
            "model": OipErrorResponse,
            "description": description,
            "content": {"application/json": {"example": {"error": message}}},
        }
    return out


def unknown_model(name: str) -> OipError:
    return OipError(f"unknown model {name!r}: this server serves {' and '.join(oip.MODELS)}", 404)


@oip_router.get(
    "/v2",
    response_model=ServerMetadata,
    responses=oip_errors(401),
    summary="Server metadata",
    name="oip_server_metadata",
    openapi_extra=curl_sample("/v2"),
)
async def server_metadata() -> dict[str, Any]:
    """The protocol's server metadata: name, version of curve-vae, and no protocol extensions."""
    from curve_vae import __version__

    return {"name": "curve-vae", "version": __version__, "extensions": []}


@oip_router.get(
    "/v2/health/live",
    response_model=Live,
    summary="Server live",
    name="oip_live",
    openapi_extra=curl_sample("/v2/health/live"),
)
async def live() -> dict[str, bool]:
    """200 while the process serves requests, like /health. Needs no API key."""
    return {"live": True}


@oip_router.get(
    "/v2/health/ready",
    response_model=Ready,
    responses=oip_errors(503),
    summary="Server ready",
    name="oip_ready",
    openapi_extra=curl_sample("/v2/health/ready"),
)
async def ready(request: Request) -> dict[str, bool]:
    """200 once the model is loaded and warmed up, like /ready; 503 before that and while shutting down. Needs no
    API key."""
    runtime_of(request)
    return {"ready": True}


def _session(request: Request, model: str) -> Any:
    runtime = runtime_of(request)
    return runtime, (runtime.graphs.encoder if model == "encoder" else runtime.graphs.decoder)


def _metadata_route(model: str) -> Callable[[Request], Awaitable[dict[str, Any]]]:
    async def model_metadata(request: Request) -> dict[str, Any]:
        runtime, session = _session(request, model)
        return oip.metadata(model, runtime.manifest.version, oip.signature(session))

    model_metadata.__doc__ = (
        f"The {model}'s inputs and outputs (name, datatype, shape with -1 for the batch axis), read from its ONNX "
        "session, and the model's version."
    )
    return model_metadata


def _ready_route(model: str) -> Callable[[Request], Awaitable[dict[str, Any]]]:
    async def model_ready(request: Request) -> dict[str, Any]:
        runtime_of(request)
        return {"name": model, "ready": True}

    model_ready.__doc__ = f"200 once the {model} is loaded, 503 before that."
    return model_ready


async def _infer_request(request: Request, model: str, session: Any) -> oip.Request:
    """The body of an infer request, checked against the session's tensors; OipError says what does not fit."""
    if "inference-header-content-length" in request.headers:
        raise OipError(
            "binary tensor data (Triton's binary data extension) is not served here: send JSON tensors "
            "(tritonclient.http: binary_data=False on every InferInput and InferRequestedOutput)"
        )
    try:
        body = json.loads(await request.body())
    except (ValueError, RecursionError) as e:
        raise OipError(f"body: not JSON ({e})") from None
    return oip.parse_request(body, model, oip.signature(session), max_batch=request.app.state.settings.max_curves)


def _infer_route(model: str) -> Callable[[Request], Awaitable[Response]]:
    graph = "curves (B, n_points, 2) → mean, log_var" if model == "encoder" else "latent → curves, control_points"

    async def model_infer(request: Request) -> Response:
        try:
            runtime, session = _session(request, model)
            req = await _infer_request(request, model, session)
            version = runtime.manifest.version

            def work() -> Response:
                graphs = runtime.graphs
                own = graphs.encoder if model == "encoder" else graphs.decoder  # this inference thread's session
                result = oip.infer(own, req, batch_size=graphs.batch_size)
                return JSON(oip.response(model, version, req, result))

            return await run_inference(request, f"/v2/models/{model}/infer", req.batch, work)
        except OipError as e:
            return oip_error(e.status, e.msg)

    model_infer.__doc__ = (
        f"Run the {model} graph ({graph}) on tensors in the protocol's JSON format; each output comes back "
        f"flattened row-major with its shape. {RAW_TENSORS} Batches of up to CURVE_VAE_MAX_CURVES rows, run like "
        "every other model route (same inference threads, slots and queue). Triton's binary data extension is not "
        "served: JSON tensors only."
    )
    return model_infer


def _model_routes(model: str) -> None:
    """The protocol's three routes of one model: metadata, ready and infer."""
    oip_router.add_api_route(
        f"/v2/models/{model}",
        _metadata_route(model),
        methods=["GET"],
        response_model=ModelMetadata,
        responses=oip_errors(401, 503),
        summary=f"{model.capitalize()} metadata",
        name=f"oip_{model}_metadata",
        openapi_extra=curl_sample(f"/v2/models/{model}"),
    )
    oip_router.add_api_route(
        f"/v2/models/{model}/ready",
        _ready_route(model),
        methods=["GET"],
        response_model=ModelReady,
        responses=oip_errors(401, 503),
        summary=f"{model.capitalize()} ready",
        name=f"oip_{model}_ready",
        openapi_extra=curl_sample(f"/v2/models/{model}/ready"),
    )
    oip_router.add_api_route(
        f"/v2/models/{model}/infer",
        _infer_route(model),
        methods=["POST"],
        response_model=InferResponse,
        responses=oip_errors(400, 401, 413, 503, 504),
        summary=f"{model.capitalize()} inference on raw tensors",
        name=f"oip_{model}_infer",
        # the request body's schema and examples are the model's tensors: service.oip_docs.describe states them
        openapi_extra=curl_sample(f"/v2/models/{model}/infer", "@request.json"),
    )


for _model in oip.MODELS:
    _model_routes(_model)


def _unknown(suffix: str) -> Callable[[str], Awaitable[Response]]:
    async def unknown(name: str) -> Response:
        e = unknown_model(name)
        return oip_error(e.status, e.msg)

    unknown.__name__ = f"oip_unknown_model{suffix.replace('/', '_')}"
    return unknown


# Every other model name: the protocol's 404 naming the models there are (after the routes above, which match first).
for _suffix, _method in (("", "GET"), ("/ready", "GET"), ("/infer", "POST")):
    oip_router.add_api_route(
        "/v2/models/{name}" + _suffix, _unknown(_suffix), methods=[_method], include_in_schema=False
    )
