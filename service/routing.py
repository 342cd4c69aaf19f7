"""How every POST route that takes a request model is built, one way: `model_route` registers a handler
`(request, req, curves)` whose request is already validated and within every limit (service.limits.check_request:
the settings' bounds, refine's work, /augment's format), for a JSON body of `model`, and, with `npy`, for the curves
as a .npy body with the other fields in the query (below). The OpenAPI operation documents both.

    @model_route(router, "/reconstruct", s.ReconstructRequest, npy=True, examples=docs.RECONSTRUCT, ...)
    async def reconstruct(request, req, curves): ...

How a route reads its body lives here too (sections below): JSON parsed and answered by orjson (`FastJSONRoute`,
`JSON`), and the curves as a .npy body (`NpyRoute`).
"""

from __future__ import annotations

import inspect
import io
import json
from collections.abc import Awaitable, Callable, Coroutine
from dataclasses import dataclass
from typing import Annotated, Any

import numpy as np
import orjson
from fastapi import APIRouter, Body, Request
from fastapi.exceptions import RequestValidationError
from fastapi.responses import JSONResponse, Response
from fastapi.routing import APIRoute
from pydantic import BaseModel, ValidationError

from curve_vae.geometry.adapt import COINCIDENT, coincident
from curve_vae.inference.errors import InputError
from curve_vae.service import limits
from curve_vae.service.deps import warmed
from curve_vae.service.settings import Settings

Handler = Callable[[Request, Any, list[np.ndarray]], Awaitable[Response]]


def model_route(
    router: APIRouter,
    path: str,
    model: type[BaseModel],
    *,
    npy: bool = False,
    examples: dict[str, Any] | None = None,
    openapi_extra: dict[str, Any] | None = None,
    **route: Any,
) -> Callable[[Handler], Handler]:
    """Register `handler(request, req, curves)` at POST `path`; `curves` are the request's curves as float64 arrays
    (empty for a model without `curves`)."""
    takes_curves = "curves" in model.model_fields

    def register(handler: Handler) -> Handler:
        async def endpoint(request: Request, req: Any) -> Response:
            curves = limits.curves_of(req) if takes_curves else []
            limits.check_request(req, request.app.state.settings, curves)
            await warmed(request)
            return await handler(request, req, curves)

        endpoint.__name__, endpoint.__doc__ = handler.__name__, handler.__doc__
        body = Annotated[model, Body(openapi_examples=examples)] if examples else model
        # a function declares no __signature__, but inspect.signature (so FastAPI) reads the one set here
        endpoint.__signature__ = inspect.Signature(  # type: ignore[attr-defined]
            [
                inspect.Parameter("request", inspect.Parameter.POSITIONAL_OR_KEYWORD, annotation=Request),
                inspect.Parameter("req", inspect.Parameter.POSITIONAL_OR_KEYWORD, annotation=body),
            ]
        )
        extra = (OPENAPI_BODY if npy else {}) | (openapi_extra or {})
        router.post(path, openapi_extra=extra or None, **route)(endpoint)
        if npy:
            router.routes[-1].npy = NpyRoute(model, handler)  # type: ignore[attr-defined]  # our mark on the route
        return handler

    return register


# JSON in and out with orjson: the stdlib's encoder and parser cost more than the model at single-curve sizes.
#
# Measured for a 128-curve /reconstruct body on this project's 2-core machine: `json.dumps` of the answer
# ≈68 ms, orjson ≈8 ms (the same bytes); `json.loads` of the request ≈40–55 ms, orjson ≈8–20 ms. The parser
# falls back to the stdlib's for what orjson refuses (NaN, Infinity: not JSON, but Python reads them), so
# those still get the schema's "not a finite number" with the point's location.
#

OPTIONS = orjson.OPT_SERIALIZE_NUMPY | orjson.OPT_NON_STR_KEYS


def loads(body: bytes) -> Any:
    """orjson, or the stdlib where orjson refuses (its errors are the ones FastAPI reports)."""
    try:
        return orjson.loads(body)
    except orjson.JSONDecodeError:
        return json.loads(body)


class JSON(JSONResponse):
    """A JSON response rendered by orjson (numpy arrays too, C-contiguous ones without a copy to lists)."""

    def render(self, content: Any) -> bytes:
        return orjson.dumps(content, option=OPTIONS)


class _Request(Request):
    async def json(self) -> Any:
        if not hasattr(self, "_json"):
            self._json = loads(await self.body())
        return self._json


class FastJSONRoute(APIRoute):
    """A route whose JSON request body is parsed by orjson; a .npy body goes to the route's .npy handler, if it
    has one (below)."""

    def get_route_handler(self) -> Callable[[Request], Coroutine[Any, Any, Response]]:
        handler = super().get_route_handler()

        async def route_handler(request: Request) -> Response:
            npy = getattr(self, "npy", None)  # set by routing.model_route(..., npy=True)
            if npy is not None and is_npy(request):
                return await dispatch(request, npy)
            return await handler(_Request(request.scope, request.receive))

        return route_handler


# .npy request bodies (Content-Type: application/x-npy) on the curve routes: the curves as one binary array.
#
# `POST /reconstruct?pose=as_is` with a .npy body of shape (B, n, 2) (or (n, 2), one curve), float32 or float64,
# is the JSON request `{"curves": <the array>, "pose": "as_is"}`: the other fields come from the query string,
# each a JSON value (`n_points=100`, `metrics=true`, `weights=[[0.5,0.5]]`) or else a string (`frame=model`).
# The curves skip JSON parsing and per-number validation: numpy checks them at once, and each refusal is a 422
# naming what is wrong (the header, the dtype, the shape, or the curve and point that is not finite).
# The answer is the same JSON as for a JSON request: service.routing.model_route registers one handler for both bodies.
#

MEDIA_TYPE = "application/x-npy"
MAGIC = b"\x93NUMPY"
_PLACEHOLDER = [[0.0, 0.0], [1.0, 0.0], [2.0, 0.0], [3.0, 0.0]]  # stands for each posted curve in the schema check

#: requestBody content for a route's OpenAPI operation (merged into openapi_extra)
OPENAPI_BODY = {
    "requestBody": {
        "content": {
            MEDIA_TYPE: {
                "schema": {
                    "type": "string",
                    "format": "binary",
                    "description": "The curves as a .npy file: float32 or float64 of shape (curves, points, 2) or "
                    "(points, 2); the other fields as query parameters, each a JSON value or a string.",
                }
            }
        }
    }
}


@dataclass(frozen=True)
class NpyRoute:
    model: type[BaseModel]  # the JSON request body the query fields are checked against
    handler: Handler  # (request, validated request model, curves) -> the response


def is_npy(request: Request) -> bool:
    return request.headers.get("content-type", "").split(";")[0].strip().lower() == MEDIA_TYPE


async def dispatch(request: Request, route: NpyRoute) -> Response:
    """Read and check the curves, check the query fields against the route's schema, run the handler."""
    settings: Settings = request.app.state.settings
    curves = read_curves(await request.body(), route.model.__name__, settings)
    fields: dict[str, Any] = {k: _query_value(v) for k, v in request.query_params.items()}
    try:
        req = route.model.model_validate({**fields, "curves": [_PLACEHOLDER] * len(curves)})
    except ValidationError as e:
        errors = [{**err, "loc": ("query", *err["loc"])} for err in e.errors() if err["loc"][:1] != ("curves",)]
        raise RequestValidationError(errors or e.errors()) from None
    limits.check_request(req, settings, curves, skip=("curves",))
    await warmed(request)
    return await route.handler(request, req, curves)


def _query_value(text: str) -> Any:
    try:
        return orjson.loads(text)
    except orjson.JSONDecodeError:
        return text


def read_curves(body: bytes, model: str, settings: Settings) -> list[np.ndarray]:
    """The curves of a .npy body, float64, each (n, 2); InputError naming what is wrong."""
    if not body.startswith(MAGIC):
        raise InputError(("body",), f"not a .npy file (Content-Type {MEDIA_TYPE}): it must start with \\x93NUMPY")
    buf = io.BytesIO(body)
    try:
        version = np.lib.format.read_magic(buf)
        read = np.lib.format.read_array_header_1_0 if version == (1, 0) else np.lib.format.read_array_header_2_0
        shape, fortran, dtype = read(buf)
    except (ValueError, SyntaxError) as e:
        raise InputError(("body",), f"a .npy header numpy cannot read: {e}") from None
    if dtype.kind != "f" or dtype.itemsize not in (4, 8):
        raise InputError(("body",), f"dtype {dtype.str}: send float32 or float64 (<f4 or <f8)")
    if len(shape) == 2:
        shape = (1, *shape)
    if len(shape) != 3 or shape[2] != 2:
        raise InputError(("body",), f"shape {shape}: expected (curves, points, 2) or (points, 2)")
    count, points = shape[0], shape[1]
    if count < 1:
        raise InputError(("curves",), "no curves: the array's first axis is 0")
    if points < 4:
        raise InputError(("curves",), f"at least 4 points per curve, got {points}")
    limits.check_shape(model, count, points, settings)
    data = body[buf.tell() :]
    expected = count * points * 2 * dtype.itemsize
    if len(data) != expected:
        raise InputError(("body",), f"{len(data)} bytes of data, the header's shape {shape} needs {expected}")
    a = np.frombuffer(data, dtype=dtype).reshape(shape, order="F" if fortran else "C").astype(np.float64)
    finite = np.isfinite(a)
    if not finite.all():
        i, j, k = np.argwhere(~finite)[0]
        raise InputError(("curves", int(i), int(j), int(k)), "not a finite number")
    coincide = coincident(list(a))
    if coincide.any():
        raise InputError(("curves", int(np.argmax(coincide))), COINCIDENT.format(n=points))
    return list(a)
