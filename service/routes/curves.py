"""The model's curve routes: encode, decode, reconstruct, interpolate. Each is built by service.routing.model_route
(the request validated and within its limits; curves as JSON or, but for decode, a .npy body), calls the runtime in a
worker thread (deps.run_inference) and answers the body inference.results builds; the OpenAPI examples are
service.api_docs'."""

from __future__ import annotations

import numpy as np
from fastapi import APIRouter, Request
from fastapi.responses import Response

from curve_vae.inference import answers
from curve_vae.inference.errors import InputError
from curve_vae.inference.results import Reconstruction, decode_body, encode_body, interpolate_body, reconstruct_body
from curve_vae.service import api_docs as docs
from curve_vae.service import schemas as s
from curve_vae.service.deps import coalesced, encode_key, reconstruct_key, run_inference, runtime_of, settings_of
from curve_vae.service.limits import check_output, check_weights
from curve_vae.service.routing import JSON, FastJSONRoute, model_route

curves_router = APIRouter(route_class=FastJSONRoute, tags=["curves"])


@model_route(
    curves_router,
    "/encode",
    s.EncodeRequest,
    npy=True,
    examples=docs.ENCODE,
    openapi_extra=docs.curl_sample("/encode", docs.ONE_CURVE),
    response_model=answers.EncodeResponse,
    responses=docs.POST_ERRORS,
    summary="Latent mean and log-variance of each curve",
)
async def encode(request: Request, req: s.EncodeRequest, curves: list[np.ndarray]) -> Response:
    """Encode curves (any frame, any length ≥ 4) into the latent space (the encoder's mean and log-variance).
    The curves may also be posted as a .npy body (`Content-Type: application/x-npy`), the other fields in the query."""
    return await coalesced(request, "/encode", encode_key(req.reading()), curves, lambda enc: JSON(encode_body(enc)))


@model_route(
    curves_router,
    "/decode",
    s.DecodeRequest,
    examples=docs.DECODE,
    response_model=answers.CurvesResponse,
    responses=docs.POST_ERRORS,
    summary="Curves for latent vectors",
    openapi_extra=docs.curl_sample("/decode", '{"latents": [[' + ",".join(["0"] * 32) + ']], "n_points": 50}'),
)
async def decode(request: Request, req: s.DecodeRequest, _curves: list[np.ndarray]) -> Response:
    """Decode latent vectors (length latent_dim, see GET /model) into curves: the model's 128×128 plane, or `frames`."""
    runtime = runtime_of(request)
    for i, z in enumerate(req.latents):
        if len(z) != runtime.latent_dim:
            raise InputError(
                ("latents", i), f"expected {runtime.latent_dim} numbers (the model's latent_dim), got {len(z)}"
            )
    if req.frames is not None and len(req.frames) != len(req.latents):
        raise InputError(("frames",), f"expected one frame per latent ({len(req.latents)}), got {len(req.frames)}")
    check_output(req.output, runtime)
    frames = [f.frame() for f in req.frames] if req.frames else None

    def work() -> Response:
        made = runtime.decode(
            np.array(req.latents, np.float64), n_points=req.n_points, spacing=req.spacing, frames=frames
        )
        return JSON(decode_body(made, metrics=req.metrics, output=req.output))

    return await run_inference(request, "/decode", len(req.latents), work)


@model_route(
    curves_router,
    "/reconstruct",
    s.ReconstructRequest,
    npy=True,
    examples=docs.RECONSTRUCT,
    openapi_extra=docs.curl_sample("/reconstruct", docs.ONE_CURVE),
    response_model=answers.ReconstructResponse,
    responses=docs.POST_ERRORS,
    summary="Pass curves through the VAE",
)
async def reconstruct(request: Request, req: s.ReconstructRequest, curves: list[np.ndarray]) -> Response:
    """Encode each curve's latent mean and decode it: the reconstruction in the caller's frame, and its MSE there.
    The curves may also be posted as a .npy body (`Content-Type: application/x-npy`), the other fields in the query."""
    check_output(req.output, runtime_of(request))

    def render(rec: Reconstruction) -> Response:
        return JSON(reconstruct_body(rec, metrics=req.metrics, output=req.output))

    return await coalesced(request, "/reconstruct", reconstruct_key(req.reading(), req.n_points), curves, render)


@model_route(
    curves_router,
    "/interpolate",
    s.InterpolateRequest,
    npy=True,
    examples=docs.INTERPOLATE,
    openapi_extra=docs.curl_sample("/interpolate", docs.TWO_CURVES[:-1] + ', "steps": 5}'),
    response_model=answers.InterpolateResponse,
    responses=docs.POST_ERRORS,
    summary="Curves between curves, by mixing latent means",
)
async def interpolate(request: Request, req: s.InterpolateRequest, curves: list[np.ndarray]) -> Response:
    """Decode affine combinations of the curves' latent means; with frame "auto" each result is mapped
    into the same blend of the inputs' frames. The curves may also be posted as a .npy body
    (`Content-Type: application/x-npy`), the other fields in the query."""
    runtime = runtime_of(request)
    weights = check_weights(req, settings_of(request))
    check_output(req.output, runtime)

    def work() -> Response:
        mix = runtime.interpolate(curves, weights, req.reading(), n_points=req.n_points)
        return JSON(interpolate_body(mix, metrics=req.metrics, output=req.output))

    return await run_inference(request, "/interpolate", len(weights), work)
