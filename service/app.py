"""The REST service: `create_app(settings)` builds a FastAPI app serving the VAE (v1 contract, DESIGN.md).

Routes are thin: the schema validates, `_check_*` applies the limits that depend on the
settings or the model, the `CurveRuntime` on `app.state` computes in a worker thread, and
the route shapes the JSON. The model is loaded in the lifespan, once per worker process,
never at import time. Every rejected request gets the same JSON error body:
`{"detail": "curves[2][17][1]: not a finite number", "errors": [{"loc": ..., "msg": ...}]}`.
"""

from __future__ import annotations

import logging
import math
import time
from collections.abc import AsyncIterator, Callable, Sequence
from contextlib import asynccontextmanager
from functools import partial
from typing import Annotated, Any

import anyio
import numpy as np
import onnxruntime as ort
from fastapi import APIRouter, Body, Depends, FastAPI, Request
from fastapi.exceptions import RequestValidationError
from fastapi.middleware.cors import CORSMiddleware
from fastapi.responses import JSONResponse, Response, StreamingResponse
from starlette.exceptions import HTTPException
from starlette.types import ASGIApp, Message, Receive, Scope, Send

from geometry import Frame, revolve
from service import schemas as s
from service.access import ApiKeyMiddleware
from service.metrics import Metrics, MetricsMiddleware
from service.npy import MEDIA_TYPE as NPY_MEDIA_TYPE
from service.npy import chunk_bytes, npy_header, npy_size
from service.openapi import state_bounds
from service.payloads import augment_body, fit_body, frames_json, sample_body, with_metrics, with_output
from service.runtime import (
    AugmentPlan,
    CurveRuntime,
    InputError,
    ModelLoadError,
    Spline,
    format_loc,
    fresh_seed,
    simplex_grid,
    simplex_grid_size,
)
from service.settings import Settings, get_settings
from service.web import mount_web

log = logging.getLogger("service")

DEFAULT_STEPS = 5  # the paper interpolates in five steps (§4)
WEIGHT_SUM_TOLERANCE = 1e-6
MAX_ERRORS_SHOWN = 20

# --------------------------------------------------------------------------- errors


def error_response(
    status: int, errors: Sequence[tuple[str, str]], *, detail: str | None = None, headers: dict[str, str] | None = None
) -> JSONResponse:
    """The one error body of the API: a line naming the first problem, and the list of all of them."""
    items = [{"loc": loc, "msg": msg} for loc, msg in errors[:MAX_ERRORS_SHOWN]]
    if detail is None:
        loc, msg = errors[0]
        detail = f"{loc}: {msg}" if loc else msg
    return JSONResponse({"detail": detail, "errors": items}, status_code=status, headers=headers)


def _validation_message(err: dict[str, Any], request: Request) -> tuple[str, str]:
    loc = list(err["loc"])
    if loc[:1] == ["body"]:
        loc = loc[1:]
    kind, ctx = err["type"], err.get("ctx") or {}
    if kind == "json_invalid":
        return "body", f"invalid JSON ({ctx.get('error', 'cannot parse')}) at position {loc[0] if loc else 0}"
    if kind in ("model_attributes_type", "dict_type", "model_type") and not loc:
        hint = ""
        if "json" not in request.headers.get("content-type", "json"):
            hint = "; send it with the header Content-Type: application/json"
        return "body", "expected a JSON object" + hint
    messages = {
        "finite_number": "not a finite number",
        "float_parsing": "not a number",
        "float_type": "not a number",
        "int_parsing": "not an integer",
        "int_type": "not an integer",
        "int_from_float": "not an integer",
        "missing": "field required",
        "extra_forbidden": "unknown field",
    }
    msg = messages.get(kind, err["msg"])
    if kind == "float_type" and isinstance(err.get("input"), int) and not isinstance(err.get("input"), bool):
        msg = "not a finite number: too large for a float"
    if kind == "too_short" and len(loc) == 2 and loc[0] == "curves" and isinstance(loc[1], int):
        msg = f"a curve needs at least 4 points, got {ctx.get('actual_length')}"
    elif kind in ("too_short", "too_long") and len(loc) == 3 and loc[0] == "curves":
        msg = f"a point is [x, y]: exactly 2 numbers, got {ctx.get('actual_length')}"
    elif kind == "tuple_type" or (kind == "list_type" and len(loc) == 3 and loc[0] == "curves"):
        msg = "a point is [x, y]: exactly 2 numbers"
    return format_loc(loc), msg


async def _on_validation_error(request: Request, exc: Exception) -> Response:
    assert isinstance(exc, RequestValidationError)
    return error_response(422, [_validation_message(e, request) for e in exc.errors()])


async def _on_input_error(request: Request, exc: Exception) -> Response:
    assert isinstance(exc, InputError)
    return error_response(422, [(format_loc(exc.loc), exc.msg)])


async def _on_http_error(request: Request, exc: Exception) -> Response:
    assert isinstance(exc, HTTPException)
    if exc.status_code == 400 and exc.detail == "There was an error parsing the body":
        # FastAPI's answer to bodies json.loads rejects with something other than a syntax error
        # (an integer of over 4300 digits): the same 422 as any other unreadable JSON.
        return error_response(422, [("body", "invalid JSON (cannot parse the body)")])
    return error_response(exc.status_code, [], detail=str(exc.detail), headers=exc.headers)


# --------------------------------------------------------------------------- body size limit


class BodyLimitMiddleware:
    """413 for bodies over the limit: by Content-Length before reading, or once a streamed body passes it."""

    def __init__(self, app: ASGIApp, *, max_body_bytes: int) -> None:
        self.app, self.limit = app, max_body_bytes

    def _too_large(self, size: str) -> JSONResponse:
        return error_response(
            413, [("body", f"{size} exceeds the limit of {self.limit} bytes (CURVE_VAE_MAX_BODY_BYTES)")]
        )

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] != "http":
            await self.app(scope, receive, send)
            return
        declared = dict(scope["headers"]).get(b"content-length", b"")
        if declared.isdigit() and int(declared) > self.limit:  # refuse before reading a byte of it
            await self._too_large(f"a body of {int(declared)} bytes")(scope, receive, send)
            return
        # Read the whole body (it is small: bounded by the limit) and replay it to the app.
        chunks, size, more = [], 0, True
        while more:
            message = await receive()
            if message["type"] != "http.request":  # client went away
                await self.app(scope, _replay([message], receive), send)
                return
            chunks.append(message.get("body", b""))
            size += len(chunks[-1])
            more = message.get("more_body", False)
            if size > self.limit:
                await self._too_large(f"a streamed body of more than {size} bytes")(scope, receive, send)
                return
        await self.app(
            scope, _replay([{"type": "http.request", "body": b"".join(chunks), "more_body": False}], receive), send
        )


def _replay(messages: list[Message], receive: Receive) -> Receive:
    async def replayed() -> Message:
        return messages.pop(0) if messages else await receive()

    return replayed


# --------------------------------------------------------------------------- dependencies and checks


def settings_of(request: Request) -> Settings:
    return request.app.state.settings


def runtime_of(request: Request) -> CurveRuntime:
    if not request.app.state.ready or request.app.state.runtime is None:
        raise HTTPException(503, "the model is not loaded yet; GET /ready answers 200 once it is")
    return request.app.state.runtime


SettingsDep = Annotated[Settings, Depends(settings_of)]
RuntimeDep = Annotated[CurveRuntime, Depends(runtime_of)]


def _check_curves(curves: list[list[tuple[float, float]]], settings: Settings) -> list[np.ndarray]:
    if len(curves) > settings.max_curves:
        raise InputError(("curves",), f"at most {settings.max_curves} curves per request, got {len(curves)}")
    for i, curve in enumerate(curves):
        if len(curve) > settings.max_points:
            raise InputError(("curves", i), f"at most {settings.max_points} points per curve, got {len(curve)}")
    return [np.asarray(c, dtype=np.float64) for c in curves]


def _check_n_points(n_points: int | None, settings: Settings) -> None:
    if n_points is not None and n_points > settings.max_points:
        raise InputError(("n_points",), f"at most {settings.max_points}, got {n_points}")


def _check_weights(req: s.InterpolateRequest, settings: Settings) -> np.ndarray:
    n = len(req.curves)
    if req.weights is None:
        steps = req.steps if req.steps is not None else DEFAULT_STEPS
        rows = simplex_grid_size(n, steps)
        if rows > settings.max_curves:
            raise InputError(
                ("steps",),
                f"{steps} steps over {n} curves make {rows} curves; at most {settings.max_curves} per response",
            )
        return simplex_grid(n, steps)
    if len(req.weights) > settings.max_curves:
        raise InputError(("weights",), f"at most {settings.max_curves} rows, got {len(req.weights)}")
    for r, row in enumerate(req.weights):
        if len(row) != n:
            raise InputError(("weights", r), f"expected {n} numbers, one per input curve, got {len(row)}")
        try:
            total = math.fsum(row)
        except OverflowError:  # terms near the float limit
            total = math.inf
        if not abs(total - 1.0) <= WEIGHT_SUM_TOLERANCE:
            raise InputError(("weights", r), f"weights must sum to 1, got {total:.9g}")
    return np.array(req.weights, dtype=np.float64)


def _splines_wanted(output: str, runtime: CurveRuntime) -> list[Spline] | None:
    """A list for the runtime to fill with splines when the request asks for them; None for points only."""
    if output == "points":
        return None
    if not runtime.has_splines:
        raise InputError(
            ("output",),
            f'"{output}" needs a model with a B-spline head, and this one has none (GET /model: spline is null); '
            'ask for "points", or fit splines to the points with /fit',
        )
    return []


def _limiter(request: Request) -> anyio.CapacityLimiter | None:
    return getattr(request.app.state, "limiter", None)  # set by the lifespan; None: anyio's default


async def _run(request: Request, route: str, batch: int, work: Callable[[], Response]) -> Response:
    """Run `work` (inference and JSON rendering) in a worker thread, never on the event loop; timed, and at
    most `inference_concurrency` at once.

    Bounded both ways: with `inference_concurrency + max_queue` requests already in here, a new one is
    answered 503 with Retry-After at once instead of joining an ever longer queue; one that takes longer
    than `request_timeout` seconds (queueing included) is answered 504 (its thread finishes on its own).
    """
    settings: Settings = request.app.state.settings
    state = request.app.state
    if getattr(state, "pending", 0) >= settings.inference_concurrency + settings.max_queue:
        raise HTTPException(
            503,
            f"busy: {state.pending} requests are running or queued (CURVE_VAE_INFERENCE_CONCURRENCY "
            f"{settings.inference_concurrency} + CURVE_VAE_MAX_QUEUE {settings.max_queue}); retry in a moment",
            headers={"Retry-After": "1"},
        )
    metrics: Metrics = state.metrics
    metrics.batch_size.labels(route).observe(batch)
    state.pending = getattr(state, "pending", 0) + 1
    start = time.perf_counter()
    try:
        with anyio.fail_after(settings.request_timeout or None):
            return await anyio.to_thread.run_sync(work, limiter=_limiter(request), abandon_on_cancel=True)
    except TimeoutError:
        raise HTTPException(
            504, f"the request took longer than {settings.request_timeout:g} s (CURVE_VAE_REQUEST_TIMEOUT); send less"
        ) from None
    finally:
        state.pending -= 1
        metrics.inference.labels(route).observe(time.perf_counter() - start)


# --------------------------------------------------------------------------- OpenAPI documentation

_ERR_EXAMPLES = {
    413: (
        "Request body over CURVE_VAE_MAX_BODY_BYTES.",
        "body: a body of 9000000 bytes exceeds the limit of 8388608 bytes (CURVE_VAE_MAX_BODY_BYTES)",
        "body",
    ),
    422: (
        "Invalid input; the message names the field, curve and point.",
        "curves[0][3][1]: not a finite number",
        "curves[0][3][1]",
    ),
    503: (
        "The model is not loaded yet (see GET /ready), or the server is busy: more requests than "
        "CURVE_VAE_INFERENCE_CONCURRENCY + CURVE_VAE_MAX_QUEUE are running or queued (then with Retry-After).",
        "the model is not loaded yet; GET /ready answers 200 once it is",
        None,
    ),
    401: (
        "The server needs an API key (CURVE_VAE_API_KEYS) and the request sent none or a wrong one.",
        "this service needs an API key: send Authorization: Bearer <key> or X-API-Key: <key>",
        None,
    ),
    504: (
        "The request took longer than CURVE_VAE_REQUEST_TIMEOUT seconds, queueing included.",
        "the request took longer than 60 s (CURVE_VAE_REQUEST_TIMEOUT); send less",
        None,
    ),
}


def _errors(*codes: int) -> dict[int | str, dict[str, Any]]:
    out: dict[int | str, dict[str, Any]] = {}
    for code in codes:
        description, detail, loc = _ERR_EXAMPLES[code]
        errors = [{"loc": loc, "msg": detail.split(": ", 1)[1]}] if loc else []
        out[code] = {
            "model": s.ErrorResponse,
            "description": description,
            "content": {"application/json": {"example": {"detail": detail, "errors": errors}}},
        }
    return out


def _curl(path: str, body: str | None = None) -> dict[str, Any]:
    source = f"curl -s http://127.0.0.1:8000{path}"
    if body is not None:
        source += f" -H 'Content-Type: application/json' -d '{body}'"
    return {"x-codeSamples": [{"lang": "Shell", "label": "curl", "source": source}]}


def _example(summary: str, value: dict[str, Any]) -> dict[str, Any]:
    return {"summary": summary, "value": value}


_C1, _C2, _C3 = s.EXAMPLE_CURVE, s.EXAMPLE_CURVE_2, s.EXAMPLE_CURVE_3
_POST_ERRORS = _errors(401, 413, 422, 503, 504)

# --------------------------------------------------------------------------- routes

curves_router = APIRouter(tags=["curves"])
ops_router = APIRouter(tags=["operations"])


@curves_router.post(
    "/encode",
    response_model=s.EncodeResponse,
    responses=_POST_ERRORS,
    summary="Latent mean and log-variance of each curve",
    openapi_extra=_curl("/encode", '{"curves": [[[0,0],[1,2],[2.5,3.2],[4,3.5],[5.5,3],[7,1.5],[8,0]]]}'),
)
async def encode(
    request: Request,
    runtime: RuntimeDep,
    settings: SettingsDep,
    req: Annotated[
        s.EncodeRequest,
        Body(
            openapi_examples={
                "one curve": _example("A curve in its own frame", {"curves": [_C1]}),
                "model frame": _example(
                    "Already in the 128×128 plane",
                    {"curves": [[[14, 64], [40, 100], [64, 110], [90, 95], [114, 64]]], "frame": "model"},
                ),
            }
        ),
    ],
) -> Response:
    """Encode curves (any frame, any length ≥ 4) into the latent space (the encoder's mean and log-variance)."""
    curves = _check_curves(req.curves, settings)

    def work() -> Response:
        mean, log_var, frames = runtime.encode(curves, frame=req.frame, spacing=req.spacing)
        return JSONResponse({"mean": mean.tolist(), "log_var": log_var.tolist(), "frames": frames_json(frames)})

    return await _run(request, "/encode", len(curves), work)


@curves_router.post(
    "/decode",
    response_model=s.CurvesResponse,
    responses=_POST_ERRORS,
    summary="Curves for latent vectors",
    openapi_extra=_curl("/decode", '{"latents": [[' + ",".join(["0"] * 32) + ']], "n_points": 50}'),
)
async def decode(
    request: Request,
    runtime: RuntimeDep,
    settings: SettingsDep,
    req: Annotated[
        s.DecodeRequest,
        Body(
            openapi_examples={
                "origin": _example(
                    "The centre of the latent space, 50 points", {"latents": [[0.0] * 32], "n_points": 50}
                ),
                "in a frame": _example(
                    "Mapped into a frame from /encode",
                    {"latents": [[0.0] * 32], "frames": [{"center": [4.0, 1.75], "size": 8.0}]},
                ),
            }
        ),
    ],
) -> Response:
    """Decode latent vectors (length latent_dim, see GET /model) into curves: the model's 128×128 plane, or `frames`."""
    if len(req.latents) > settings.max_curves:
        raise InputError(("latents",), f"at most {settings.max_curves} latents per request, got {len(req.latents)}")
    for i, z in enumerate(req.latents):
        if len(z) != runtime.latent_dim:
            raise InputError(
                ("latents", i), f"expected {runtime.latent_dim} numbers (the model's latent_dim), got {len(z)}"
            )
    if req.frames is not None and len(req.frames) != len(req.latents):
        raise InputError(("frames",), f"expected one frame per latent ({len(req.latents)}), got {len(req.frames)}")
    _check_n_points(req.n_points, settings)
    frames = [Frame(center=f.center, size=f.size) for f in req.frames] if req.frames else None

    splines = _splines_wanted(req.output, runtime)

    def work() -> Response:
        latents = np.array(req.latents, np.float64)
        curves = runtime.decode(latents, n_points=req.n_points, spacing=req.spacing, frames=frames, splines=splines)
        return JSONResponse(
            with_output(with_metrics({"curves": curves.tolist()}, curves, req.metrics), splines, req.output)
        )

    return await _run(request, "/decode", len(req.latents), work)


@curves_router.post(
    "/reconstruct",
    response_model=s.ReconstructResponse,
    responses=_POST_ERRORS,
    summary="Pass curves through the VAE",
    openapi_extra=_curl("/reconstruct", '{"curves": [[[0,0],[1,2],[2.5,3.2],[4,3.5],[5.5,3],[7,1.5],[8,0]]]}'),
)
async def reconstruct(
    request: Request,
    runtime: RuntimeDep,
    settings: SettingsDep,
    req: Annotated[
        s.ReconstructRequest,
        Body(
            openapi_examples={
                "one curve": _example("A curve in its own frame, back at its own 7 points", {"curves": [_C1]}),
                "resampled": _example(
                    "Two curves, returned at 100 points each", {"curves": [_C1, _C2], "n_points": 100}
                ),
                "points and spline": _example(
                    "The reconstruction as points and as the B-spline they lie on", {"curves": [_C1], "output": "both"}
                ),
            }
        ),
    ],
) -> Response:
    """Encode each curve's latent mean and decode it: the reconstruction in the caller's frame, and its MSE there."""
    curves = _check_curves(req.curves, settings)
    _check_n_points(req.n_points, settings)

    splines = _splines_wanted(req.output, runtime)

    def work() -> Response:
        out, mse = runtime.reconstruct(
            curves, frame=req.frame, n_points=req.n_points, spacing=req.spacing, splines=splines
        )
        body = with_metrics({"curves": [c.tolist() for c in out], "mse": mse.tolist()}, out, req.metrics)
        return JSONResponse(with_output(body, splines, req.output))

    return await _run(request, "/reconstruct", len(curves), work)


@curves_router.post(
    "/interpolate",
    response_model=s.InterpolateResponse,
    responses=_POST_ERRORS,
    summary="Curves between curves, by mixing latent means",
    openapi_extra=_curl(
        "/interpolate",
        '{"curves": [[[0,0],[1,2],[2.5,3.2],[4,3.5],[5.5,3],[7,1.5],[8,0]], '
        '[[0,0],[1.5,0.5],[3,2],[4,4],[5,6.5],[6.5,8],[8,8.5]]], "steps": 5}',
    ),
)
async def interpolate(
    request: Request,
    runtime: RuntimeDep,
    settings: SettingsDep,
    req: Annotated[
        s.InterpolateRequest,
        Body(
            openapi_examples={
                "pair": _example(
                    "Pair, 5 curves from the first to the second (paper eq. 9)", {"curves": [_C1, _C2], "steps": 5}
                ),
                "triplet": _example(
                    "Triplet, barycentric grid of 6 curves (paper eq. 10)", {"curves": [_C1, _C2, _C3], "steps": 3}
                ),
                "weights": _example(
                    "Explicit weights, one entry per curve", {"curves": [_C1, _C2], "weights": [[0.25, 0.75]]}
                ),
                "as B-splines": _example(
                    "The middle curve as a B-spline: control points, knots, degree and the parameter of each point",
                    {"curves": [_C1, _C2], "weights": [[0.5, 0.5]], "output": "bspline"},
                ),
            }
        ),
    ],
) -> Response:
    """Decode affine combinations of the curves' latent means; with frame "auto" each result is mapped
    into the same blend of the inputs' frames."""
    curves = _check_curves(req.curves, settings)
    _check_n_points(req.n_points, settings)
    weights = _check_weights(req, settings)

    splines = _splines_wanted(req.output, runtime)

    def work() -> Response:
        out, frames = runtime.interpolate(
            curves, weights, frame=req.frame, n_points=req.n_points, spacing=req.spacing, splines=splines
        )
        body = {"weights": weights.tolist(), "curves": out.tolist(), "frames": frames_json(frames)}
        return JSONResponse(with_output(with_metrics(body, out, req.metrics), splines, req.output))

    return await _run(request, "/interpolate", len(weights), work)


@curves_router.post(
    "/sample",
    response_model=s.SampleResponse,
    responses=_POST_ERRORS,
    summary="New curves from the learned latent distribution (or the standard prior)",
    openapi_extra=_curl("/sample", '{"count": 3, "seed": 7, "n_points": 50}'),
)
async def sample(
    request: Request,
    runtime: RuntimeDep,
    settings: SettingsDep,
    req: Annotated[
        s.SampleRequest,
        Body(
            openapi_examples={
                "seeded": _example("Three curves, reproducible", {"count": 3, "seed": 7, "n_points": 50}),
                "tame": _example("Closer to typical shapes", {"count": 2, "seed": 1, "temperature": 0.5}),
                "standard prior": _example(
                    "The VAE's N(0, I), every draw kept", {"count": 2, "seed": 1, "prior": "standard", "valid": False}
                ),
                "framed": _example(
                    "In a frame of one's own, with smoothness metrics",
                    {"count": 2, "seed": 3, "frame": {"center": [0, 0], "size": 2}, "metrics": True},
                ),
            }
        ),
    ],
) -> Response:
    """Decode latents drawn from the learned latent distribution (a Gaussian mixture fitted to the training curves'
    latent means, shipped with the model) or from the standard prior N(0, I), into curves in the model's 128×128
    plane (or `frame`). By default a curve that crosses itself or leaves the data's disc is drawn again. The same
    seed gives the same curves; without one, the response reports the seed drawn."""
    if req.count > settings.max_curves:
        raise InputError(("count",), f"at most {settings.max_curves}, got {req.count}")
    _check_n_points(req.n_points, settings)
    seed = fresh_seed() if req.seed is None else req.seed
    frame = Frame(center=req.frame.center, size=req.frame.size) if req.frame else None

    splines = _splines_wanted(req.output, runtime)

    def work() -> Response:
        made = runtime.sample(
            req.count,
            seed=seed,
            temperature=req.temperature,
            prior=req.prior,
            valid=req.valid,
            n_points=req.n_points,
            spacing=req.spacing,
            frame=frame,
            splines=splines,
        )
        return JSONResponse(with_output(sample_body(made, seed, metrics=req.metrics), splines, req.output))

    return await _run(request, "/sample", req.count, work)


_AUGMENT_NPY = {
    "description": 'format "json": the curves, their sources and weights (AugmentResponse). format "npy": the '
    "curves alone as a .npy file, float32 of shape (count, points, 2), streamed with its Content-Length.",
    "content": {NPY_MEDIA_TYPE: {"schema": {"type": "string", "format": "binary"}}},
    "headers": {
        "X-Augment-Seed": {
            "description": "The seed used (to repeat the batch, or page through it as JSON).",
            "schema": {"type": "string"},
        },
        "Content-Disposition": {"description": 'attachment; filename="augment.npy"', "schema": {"type": "string"}},
    },
}


@curves_router.post(
    "/augment",
    response_model=s.AugmentResponse,
    responses={200: _AUGMENT_NPY, **_POST_ERRORS},
    summary="New curves between given curves",
    openapi_extra=_curl(
        "/augment",
        '{"curves": [[[0,0],[1,2],[2.5,3.2],[4,3.5],[5.5,3],[7,1.5],[8,0]], '
        "[[0,0],[1.5,0.5],[3,2],[4,4],[5,6.5],[6.5,8],[8,8.5]], "
        '[[0,4],[2,5],[4,4],[6,2],[8,1],[10,2],[12,4]]], "count": 4, "mode": "triplet", "seed": 1}',
    ),
)
async def augment(
    request: Request,
    runtime: RuntimeDep,
    settings: SettingsDep,
    req: Annotated[
        s.AugmentRequest,
        Body(
            openapi_examples={
                "pairs": _example("Four random pair interpolants", {"curves": [_C1, _C2, _C3], "count": 4, "seed": 1}),
                "triplets": _example(
                    "Two random triplet interpolants", {"curves": [_C1, _C2, _C3], "count": 2, "mode": "triplet"}
                ),
                "neighbours, second page": _example(
                    "Pairs of near neighbours only; curves 4 and 5 of the seeded sequence",
                    {"curves": [_C1, _C2, _C3], "count": 2, "neighbours": 1, "seed": 1, "offset": 4},
                ),
                "npy": _example(
                    "1000 curves as a binary .npy file (curl -o batch.npy)",
                    {"curves": [_C1, _C2, _C3], "count": 1000, "seed": 1, "n_points": 64, "format": "npy"},
                ),
            }
        ),
    ],
) -> Response:
    """Random interpolants of random pairs or triplets of the curves (optionally near neighbours in latent space),
    each in the blend of its sources' frames: new training data between the given curves. Item i of the sequence
    depends only on (seed, i): page with `offset`, or stream any count as .npy with `format` "npy"."""
    curves = _check_curves(req.curves, settings)
    limit, setting = (
        (settings.max_curves, "CURVE_VAE_MAX_CURVES")
        if req.format == "json"
        else (settings.max_stream_curves, "CURVE_VAE_MAX_STREAM_CURVES")
    )
    if req.count > limit:
        more = "; page through more with offset, or stream them with format npy" if req.format == "json" else ""
        raise InputError(("count",), f"at most {limit}, got {req.count} (format {req.format}, {setting}){more}")
    if req.metrics and req.format == "npy":
        raise InputError(("metrics",), "only with format json: a .npy body carries the curves alone")
    if req.output != "points" and req.format == "npy":
        raise InputError(("output",), 'only "points" with format npy: a .npy body carries the curves\' points alone')
    splines = _splines_wanted(req.output, runtime)
    _check_n_points(req.n_points, settings)
    seed = fresh_seed() if req.seed is None else req.seed
    start, stop = req.offset, req.offset + req.count

    def plan() -> AugmentPlan:
        return runtime.plan_augment(
            curves, mode=req.mode, seed=seed, neighbours=req.neighbours, frame=req.frame, spacing=req.spacing
        )

    if req.format == "npy":
        return await _stream_augment(request, runtime, plan, req, seed)

    def work() -> Response:
        out, sources, weights, frames = runtime.augment_batch(
            plan(), start, stop, n_points=req.n_points, spacing=req.spacing, splines=splines
        )
        body = augment_body(out, sources, weights, frames, seed=seed, offset=req.offset, metrics=req.metrics)
        return JSONResponse(with_output(body, splines, req.output))

    return await _run(request, "/augment", req.count, work)


async def _stream_augment(
    request: Request, runtime: CurveRuntime, plan: Callable[[], AugmentPlan], req: s.AugmentRequest, seed: int
) -> Response:
    """The curves of a planned augmentation as a .npy body, one batch_size chunk per worker-thread call: memory stays
    bounded by a chunk whatever the count. The seed curves are encoded and the first chunk made before answering, so
    that their errors are 422s; the inference time is observed once the body is sent."""
    metrics: Metrics = request.app.state.metrics
    metrics.batch_size.labels("/augment").observe(req.count)
    busy = 0.0

    async def in_thread(fn: Callable[..., Any], *args: Any) -> Any:
        nonlocal busy
        begin = time.perf_counter()
        try:
            return await anyio.to_thread.run_sync(fn, *args, limiter=_limiter(request))
        finally:
            busy += time.perf_counter() - begin

    try:
        planned: AugmentPlan = await in_thread(plan)
        shape = (req.count, runtime.mix_length(planned.prep, req.n_points), 2)
        chunks = runtime.augment_chunks(
            planned, req.offset, req.offset + req.count, n_points=req.n_points, spacing=req.spacing
        )
        first = await in_thread(next, chunks, None)
    except BaseException:
        metrics.inference.labels("/augment").observe(busy)
        raise

    async def body() -> AsyncIterator[bytes]:
        try:
            yield npy_header(shape)
            chunk = first
            while chunk is not None:
                yield chunk_bytes(chunk, shape)
                chunk = await in_thread(next, chunks, None)
        finally:
            metrics.inference.labels("/augment").observe(busy)

    headers = {
        "Content-Length": str(npy_size(shape)),
        "Content-Disposition": 'attachment; filename="augment.npy"',
        "X-Augment-Seed": str(seed),
    }
    return StreamingResponse(body(), media_type=NPY_MEDIA_TYPE, headers=headers)


# --------------------------------------------------------------------------- design tools (no model needed)

design_router = APIRouter(tags=["design"])


@design_router.post(
    "/fit",
    response_model=s.FitResponse,
    responses=_errors(413, 422),
    summary="Least-squares cubic B-spline of each curve",
    openapi_extra=_curl("/fit", '{"curves": [[[0,0],[1,2],[2.5,3.2],[4,3.5],[5.5,3],[7,1.5],[8,0]]], "n_ctrl": 5}'),
)
async def fit(
    request: Request,
    settings: SettingsDep,
    req: Annotated[
        s.FitRequest,
        Body(
            openapi_examples={
                "automatic": _example("The fewest control points within 0.1% of the diagonal", {"curves": [_C1]}),
                "five control points": _example("A 7-point curve, 5 control points", {"curves": [_C1], "n_ctrl": 5}),
                "with the fitted curve": _example(
                    "Control polygon and the spline at 20 points", {"curves": [_C1, _C2], "n_ctrl": 6, "n_points": 20}
                ),
            }
        ),
    ],
) -> Response:
    """Clamped uniform cubic B-spline with `n_ctrl` control points (omitted: the fewest within `tolerance`) fitted to
    each curve by least squares: control points, knots, and how far the curve is from the spline."""
    curves = _check_curves(req.curves, settings)
    _check_n_points(req.n_points, settings)

    def work() -> Response:
        return JSONResponse(
            fit_body(curves, req.n_ctrl, param=req.param, n_points=req.n_points, tolerance=req.tolerance)
        )

    return await _run(request, "/fit", len(curves), work)


_MESH_TYPES = {"obj": "model/obj", "stl": "model/stl"}


@design_router.post(
    "/revolve",
    response_class=Response,
    responses={
        200: {
            "description": "The mesh file: OBJ text or binary STL. Headers X-Mesh-Vertices, X-Mesh-Faces (triangles) "
            "and X-Mesh-Closed (true when every edge joins two triangles: a watertight surface).",
            "content": {
                "model/obj": {"schema": {"type": "string"}, "example": "v 0 0 0\nv 2 0 0\n…\nf 1 3 2\n…\n"},
                "model/stl": {"schema": {"type": "string", "format": "binary"}},
            },
            "headers": {
                name: {"description": text, "schema": {"type": "string"}}
                for name, text in [
                    ("X-Mesh-Vertices", "vertex count"),
                    ("X-Mesh-Faces", "triangle count"),
                    ("X-Mesh-Closed", "true: closed and watertight; false: open at the rims of the end rings"),
                    ("Content-Disposition", 'attachment; filename="surface.obj" (or .stl)'),
                ]
            },
        },
        **_errors(413, 422),
    },
    summary="Surface of revolution of a profile curve (a vase, paper Fig. 12)",
    openapi_extra=_curl("/revolve", '{"curve": [[0,0],[3,0],[4,1],[3,3],[2.5,5],[3,7],[0,7]], "segments": 32}'),
)
async def revolve_profile(
    request: Request,
    settings: SettingsDep,
    req: Annotated[
        s.RevolveRequest,
        Body(
            openapi_examples={
                "vase": _example(
                    "A closed vase: the profile's ends lie on the axis x = 0",
                    {"curve": [[0, 0], [3, 0], [4, 1], [3, 3], [2.5, 5], [3, 7], [0, 7]], "segments": 32},
                ),
                "ring, STL": _example(
                    "An open band about the horizontal line y = -1, binary STL",
                    {"curve": _C1, "axis": "x", "axis_position": -1, "format": "stl"},
                ),
            }
        ),
    ],
) -> Response:
    """Revolve a profile about a vertical (or horizontal) line of its plane into a triangle mesh, outward-facing;
    answered as a file (OBJ text by default, or binary STL) with its vertex and triangle counts in headers."""
    if len(req.curve) > settings.max_points:
        raise InputError(("curve",), f"at most {settings.max_points} points, got {len(req.curve)}")
    profile = np.asarray(req.curve, dtype=np.float64)
    triangles = 2 * (len(profile) - 1) * req.segments  # at most: pole bands have half as many
    if triangles > settings.max_mesh_triangles:
        raise InputError(
            ("segments",),
            f"{req.segments} segments of a {len(profile)}-point profile make up to {triangles} triangles; at most "
            f"{settings.max_mesh_triangles} (CURVE_VAE_MAX_MESH_TRIANGLES)",
        )

    def work() -> Response:
        try:
            with np.errstate(all="ignore"):  # coordinates near the float limit: checked just below
                mesh = revolve(profile, segments=req.segments, axis=req.axis, axis_position=req.axis_position)
        except ValueError as e:
            raise InputError(("curve",), str(e)) from e
        if not np.isfinite(mesh.vertices).all():
            raise InputError(("curve",), "the mesh does not fit in float64: scale the profile down")
        if req.format == "stl" and not (np.abs(mesh.vertices) <= np.finfo(np.float32).max).all():
            raise InputError(("curve",), "the mesh does not fit in STL's float32: scale the profile down")
        closed = all(uses == 2 for uses in mesh.edge_use().values())
        if req.format == "stl":
            with np.errstate(all="ignore"):  # normals of huge triangles: STL readers recompute them
                content: bytes | str = mesh.to_stl()
        else:
            content = mesh.to_obj(
                comment=f"curve-vae surface of revolution: {len(profile)}-point profile, "
                f"{req.segments} segments about the {req.axis} axis"
            )
        headers = {
            "X-Mesh-Vertices": str(len(mesh.vertices)),
            "X-Mesh-Faces": str(len(mesh.faces)),
            "X-Mesh-Closed": str(closed).lower(),
            "Content-Disposition": f'attachment; filename="surface.{req.format}"',
        }
        return Response(content, media_type=_MESH_TYPES[req.format], headers=headers)

    return await _run(request, "/revolve", 1, work)


@ops_router.get("/health", response_model=s.StatusResponse, summary="Liveness", openapi_extra=_curl("/health"))
async def health() -> dict[str, str]:
    """200 while the process serves requests, model loaded or not."""
    return {"status": "ok"}


@ops_router.get(
    "/ready",
    response_model=s.StatusResponse,
    responses=_errors(503),
    summary="Readiness",
    openapi_extra=_curl("/ready"),
)
async def ready(request: Request) -> dict[str, str]:
    """200 once the model is loaded and a warm-up inference succeeded; 503 before that and while shutting down."""
    runtime_of(request)
    return {"status": "ready"}


@ops_router.get(
    "/model",
    response_model=s.ModelInfo,
    responses=_errors(503),
    summary="The model being served",
    openapi_extra=_curl("/model"),
)
async def model_info(runtime: RuntimeDep, settings: SettingsDep) -> dict[str, Any]:
    """Name, version, dimensions and checksums from the manifest, and the providers the sessions actually use."""
    m = runtime.manifest
    return {
        "name": m.get("name", "curve-vae"),
        "version": str(m.get("version", "")),
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
            {k: m["spline"][k] for k in ("n_ctrl", "degree", "knots") if k in m["spline"]} if m.get("spline") else None
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
        },
    }


@ops_router.get(
    "/metrics",
    summary="Prometheus metrics",
    response_class=Response,
    openapi_extra=_curl("/metrics"),
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


# --------------------------------------------------------------------------- the app


@asynccontextmanager
async def _lifespan(app: FastAPI) -> AsyncIterator[None]:
    settings: Settings = app.state.settings
    owned = app.state.runtime is None
    if owned:
        try:
            app.state.runtime = await anyio.to_thread.run_sync(
                partial(
                    CurveRuntime.load,
                    settings.model_dir,
                    providers=settings.providers,
                    intra_op_threads=settings.intra_op_threads,
                    batch_size=settings.batch_size,
                )
            )
        except ModelLoadError as e:
            log.error("cannot serve the model: %s", e)
            raise
    runtime: CurveRuntime = app.state.runtime
    app.state.limiter = anyio.CapacityLimiter(settings.inference_concurrency)
    app.state.ready = True
    app.state.metrics.ready.set(1)
    log.info(
        "serving %s %s from %s on %s",
        runtime.manifest.get("name"),
        runtime.manifest.get("version"),
        settings.model_dir,
        runtime.providers,
    )
    try:
        yield
    finally:
        app.state.ready = False
        app.state.metrics.ready.set(0)
        if owned:
            app.state.runtime = None


DESCRIPTION = """\
An Inception VAE for 2D curves (Barzegar Khalilsaraei & Augsdörfer, WSCG 2025) behind REST.

A curve is a JSON array of `[x, y]` points: any frame, any order of magnitude, any length ≥ 4.
Every endpoint takes a batch. With `frame: "auto"` (the default) each curve is shifted and
uniformly scaled into the model's frame and results are mapped back. Curves of any length are
resampled to the model's 161 points (`spacing`: along their parameter, like the training
data, or by arc length) and come back at their own length, or `n_points`. Errors are JSON:
`detail` names the field, curve and point.
"""


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
        openapi_tags=[
            {"name": "curves", "description": "Encode, decode, reconstruct, interpolate, sample and augment curves."},
            {"name": "design", "description": "B-spline fits and surfaces of revolution: geometry, no model needed."},
            {"name": "operations", "description": "Health, readiness, model metadata and metrics."},
        ],
    )
    app.state.settings, app.state.runtime, app.state.ready = settings, runtime, False
    app.state.metrics = Metrics()
    app.include_router(curves_router)
    app.include_router(design_router)
    app.include_router(ops_router)
    mount_web(app)
    app.add_exception_handler(RequestValidationError, _on_validation_error)
    app.add_exception_handler(InputError, _on_input_error)
    app.add_exception_handler(HTTPException, _on_http_error)
    # Added last = outermost: metrics see everything, CORS headers reach 413s too.
    app.add_middleware(BodyLimitMiddleware, max_body_bytes=settings.max_body_bytes)
    if settings.api_keys:  # outside the body limit: a request without a key is refused before its body is read
        app.add_middleware(ApiKeyMiddleware, keys=settings.api_keys)
    if settings.cors_origins:
        app.add_middleware(
            CORSMiddleware,
            allow_origins=settings.cors_origins,
            allow_methods=["GET", "POST"],
            allow_headers=["Content-Type", "Authorization", "X-API-Key"],
            # what a page on another origin needs to read (the .npy seed, the mesh counts, download names)
            expose_headers=[
                "X-Augment-Seed",
                "X-Mesh-Vertices",
                "X-Mesh-Faces",
                "X-Mesh-Closed",
                "Content-Disposition",
            ],
            max_age=600,
        )

    def openapi() -> dict[str, Any]:
        """FastAPI's schema, with the bounds of these settings and of the loaded model stated in it."""
        if app.openapi_schema is None or getattr(app.state, "openapi_for", None) != runtime_dim():
            app.openapi_schema = None
            app.state.openapi_for = runtime_dim()
            app.openapi_schema = state_bounds(FastAPI.openapi(app), settings, runtime_dim())
        return app.openapi_schema

    def runtime_dim() -> int | None:
        rt = app.state.runtime
        return rt.latent_dim if rt is not None else None

    app.openapi = openapi  # type: ignore[method-assign]
    routes = (*curves_router.routes, *design_router.routes, *ops_router.routes, *app.routes)
    paths = [r.path for r in routes if hasattr(r, "path")]
    app.add_middleware(MetricsMiddleware, metrics=app.state.metrics, known_paths=paths)
    return app


def create_app_from_env() -> FastAPI:
    """uvicorn factory for worker processes: settings from CURVE_VAE_* variables."""
    return create_app(Settings())
