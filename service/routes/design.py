"""Geometry tools that need no model: least-squares B-spline fits and surfaces of revolution (routes built by
service.routing.model_route: each request validated and within its limits before the handler runs)."""

from __future__ import annotations

import numpy as np
from fastapi import APIRouter, Request
from fastapi.responses import Response

from curve_vae.geometry import revolve
from curve_vae.inference import answers
from curve_vae.inference.errors import InputError
from curve_vae.inference.results import fit_body, mesh_file
from curve_vae.service import schemas as s
from curve_vae.service.api_docs import C1, C2, curl_sample, error_docs, example
from curve_vae.service.deps import run_inference
from curve_vae.service.routing import JSON, FastJSONRoute, model_route

design_router = APIRouter(route_class=FastJSONRoute, tags=["design"])

FIT_EXAMPLES = {
    "automatic": example("The fewest control points within 0.1% of the diagonal", {"curves": [C1]}),
    "five control points": example("A 7-point curve, 5 control points", {"curves": [C1], "n_ctrl": 5}),
    "with the fitted curve": example(
        "Control polygon and the spline at 20 points", {"curves": [C1, C2], "n_ctrl": 6, "n_points": 20}
    ),
}
REVOLVE_EXAMPLES = {
    "vase": example(
        "A closed vase: the profile's ends lie on the axis x = 0",
        {"curve": [[0, 0], [3, 0], [4, 1], [3, 3], [2.5, 5], [3, 7], [0, 7]], "segments": 32},
    ),
    "ring, STL": example(
        "An open band about the horizontal line y = -1, binary STL",
        {"curve": C1, "axis": "x", "axis_position": -1, "format": "stl"},
    ),
}


@model_route(
    design_router,
    "/fit",
    s.FitRequest,
    examples=FIT_EXAMPLES,
    response_model=answers.FitResponse,
    responses=error_docs(413, 422),
    summary="Least-squares cubic B-spline of each curve",
    openapi_extra=curl_sample(
        "/fit", '{"curves": [[[0,0],[1,2],[2.5,3.2],[4,3.5],[5.5,3],[7,1.5],[8,0]]], "n_ctrl": 5}'
    ),
)
async def fit(request: Request, req: s.FitRequest, curves: list[np.ndarray]) -> Response:
    """Clamped uniform cubic B-spline with `n_ctrl` control points (omitted: the fewest within `tolerance`) fitted to
    each curve by least squares: control points, knots, and how far the curve is from the spline."""

    def work() -> Response:
        return JSON(fit_body(curves, req.n_ctrl, param=req.param, n_points=req.n_points, tolerance=req.tolerance))

    return await run_inference(request, "/fit", len(curves), work)


MESH_TYPES = {"obj": "model/obj", "stl": "model/stl"}


@model_route(
    design_router,
    "/revolve",
    s.RevolveRequest,
    examples=REVOLVE_EXAMPLES,
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
        **error_docs(413, 422),
    },
    summary="Surface of revolution of a profile curve (a vase, paper Fig. 12)",
    openapi_extra=curl_sample("/revolve", '{"curve": [[0,0],[3,0],[4,1],[3,3],[2.5,5],[3,7],[0,7]], "segments": 32}'),
)
async def revolve_profile(request: Request, req: s.RevolveRequest, _curves: list[np.ndarray]) -> Response:
    """Revolve a profile about a vertical (or horizontal) line of its plane into a triangle mesh, outward-facing;
    answered as a file (OBJ text by default, or binary STL) with its vertex and triangle counts in headers."""
    profile = np.asarray(req.curve, dtype=np.float64)

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
        content = mesh_file(mesh, points=len(profile), segments=req.segments, axis=req.axis, fmt=req.format)
        headers = {
            "X-Mesh-Vertices": str(len(mesh.vertices)),
            "X-Mesh-Faces": str(len(mesh.faces)),
            "X-Mesh-Closed": str(closed).lower(),
            "Content-Disposition": f'attachment; filename="surface.{req.format}"',
        }
        return Response(content, media_type=MESH_TYPES[req.format], headers=headers)

    return await run_inference(request, "/revolve", 1, work)
