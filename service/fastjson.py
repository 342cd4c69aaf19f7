"""JSON in and out with orjson: the stdlib's encoder and parser cost more than the model at single-curve sizes.

Measured for a 128-curve /reconstruct body on this project's 2-core machine: `json.dumps` of the answer
≈68 ms, orjson ≈8 ms (the same bytes); `json.loads` of the request ≈40–55 ms, orjson ≈8–20 ms. The parser
falls back to the stdlib's for what orjson refuses (NaN, Infinity: not JSON, but Python reads them), so
those still get the schema's "not a finite number" with the point's location.
"""

from __future__ import annotations

import json
from collections.abc import Callable, Coroutine
from typing import Any

import orjson
from fastapi import Request
from fastapi.responses import JSONResponse, Response
from fastapi.routing import APIRoute

from curve_vae.service import npy_bodies

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
    has one (service.npy_bodies)."""

    def get_route_handler(self) -> Callable[[Request], Coroutine[Any, Any, Response]]:
        handler = super().get_route_handler()

        async def route_handler(request: Request) -> Response:
            npy = getattr(self, "npy", None)  # set by routing.model_route(..., npy=True)
            if npy is not None and npy_bodies.is_npy(request):
                return await npy_bodies.dispatch(request, npy)
            return await handler(_Request(request.scope, request.receive))

        return route_handler
