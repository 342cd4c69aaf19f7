"""How every POST route that takes a request model is built, one way: `model_route` registers a handler
`(request, req, curves)` whose request is already validated and within every limit (service.limits.check_request:
the settings' bounds, refine's work, /augment's format), for a JSON body of `model`, and, with `npy`, for the curves
as a .npy body with the other fields in the query (service.npy_bodies). The OpenAPI operation documents both.

    @model_route(router, "/reconstruct", s.ReconstructRequest, npy=True, examples=docs.RECONSTRUCT, ...)
    async def reconstruct(request, req, curves): ...
"""

from __future__ import annotations

import inspect
from collections.abc import Awaitable, Callable
from typing import Annotated, Any

import numpy as np
from fastapi import APIRouter, Body, Request
from fastapi.responses import Response
from pydantic import BaseModel

from curve_vae.service import limits
from curve_vae.service.deps import warmed
from curve_vae.service.npy_bodies import OPENAPI_BODY, NpyRoute

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
