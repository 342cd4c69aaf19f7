"""The generating routes: /sample (new curves from a latent distribution), /explore (curves around one) and /augment
(new curves between given ones, as seeded JSON pages or one streamed .npy file). Each is built by
service.routing.model_route (the request validated and within its limits), runs the runtime in a worker thread and
answers the body inference.results builds, shared with the command line."""

from __future__ import annotations

import time
from collections.abc import AsyncIterator, Callable
from typing import Any

import numpy as np
from fastapi import APIRouter, Request
from fastapi.responses import Response, StreamingResponse

from curve_vae.inference import answers
from curve_vae.inference.generation.augmenting import AugmentPlan
from curve_vae.inference.generation.sampling import fresh_seed
from curve_vae.inference.results import augment_body, explore_body, sample_body
from curve_vae.inference.runtime import CurveRuntime
from curve_vae.npy import MEDIA_TYPE as NPY_MEDIA_TYPE
from curve_vae.npy import chunk_bytes, npy_header, npy_size
from curve_vae.service import api_docs as docs
from curve_vae.service import schemas as s
from curve_vae.service.deps import in_executor, run_inference, runtime_of
from curve_vae.service.limits import check_output
from curve_vae.service.metrics import Metrics
from curve_vae.service.routing import JSON, FastJSONRoute, model_route

generate_router = APIRouter(route_class=FastJSONRoute, tags=["curves"])


@model_route(
    generate_router,
    "/sample",
    s.SampleRequest,
    examples=docs.SAMPLE,
    response_model=answers.SampleResponse,
    responses=docs.POST_ERRORS,
    summary="New curves from a latent distribution: the learned one, a named prior, or the standard prior",
    openapi_extra=docs.curl_sample("/sample", '{"count": 3, "seed": 7, "n_points": 50}'),
)
async def sample(request: Request, req: s.SampleRequest, _curves: list[np.ndarray]) -> Response:
    """Decode latents drawn from the learned latent distribution (a Gaussian mixture fitted to the training curves'
    latent means, shipped with the model) or from the standard prior N(0, I), into curves in the model's 128×128
    plane (or `frame`). By default a curve that crosses itself or leaves the data's disc is drawn again. The same
    seed gives the same curves; without one, the response reports the seed drawn."""
    runtime = runtime_of(request)
    check_output(req.output, runtime)
    seed = fresh_seed() if req.seed is None else req.seed
    frame = req.frame.frame() if req.frame else None

    def work() -> Response:
        made = runtime.sample(
            req.count,
            seed=seed,
            temperature=req.temperature,
            prior=req.prior,
            valid=req.valid,
            offset=req.offset,
            n_points=req.n_points,
            spacing=req.spacing,
            frame=frame,
        )
        return JSON(sample_body(made, metrics=req.metrics, output=req.output))

    return await run_inference(request, "/sample", req.count, work)


@model_route(
    generate_router,
    "/explore",
    s.ExploreRequest,
    examples=docs.EXPLORE,
    response_model=answers.ExploreResponse,
    responses=docs.POST_ERRORS,
    summary="Curves around one curve, along the directions the data varies most",
    openapi_extra=docs.curl_sample("/explore", docs.ONE_CURVE),
)
async def explore(request: Request, req: s.ExploreRequest, curves: list[np.ndarray]) -> Response:
    """Encode the curve, move its latent mean along the principal directions of the latent distribution (the learned
    one where the model ships it: the directions along which the training curves vary most), `steps` offsets per
    direction from −spread to spread standard deviations, and decode each in the curve's own frame. The grid's middle
    is the curve's own reconstruction; each curve says whether it crosses itself."""
    runtime = runtime_of(request)
    check_output(req.output, runtime)

    def work() -> Response:
        made = runtime.explore(
            curves[0],
            req.reading(),
            steps=req.steps,
            spread=req.spread,
            directions=req.directions,
            prior=req.prior,
            n_points=req.n_points,
        )
        return JSON(explore_body(made, metrics=req.metrics, output=req.output))

    return await run_inference(request, "/explore", req.steps**req.directions, work)


AUGMENT_NPY = {
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


@model_route(
    generate_router,
    "/augment",
    s.AugmentRequest,
    examples=docs.AUGMENT,
    response_model=answers.AugmentResponse,
    responses={200: AUGMENT_NPY, **docs.POST_ERRORS},
    summary="New curves between given curves",
    openapi_extra=docs.curl_sample("/augment", docs.THREE_CURVES[:-1] + ', "count": 4, "mode": "triplet", "seed": 1}'),
)
async def augment(request: Request, req: s.AugmentRequest, curves: list[np.ndarray]) -> Response:
    """Random interpolants of random pairs or triplets of the curves (optionally near neighbours in latent space),
    each in the blend of its sources' frames: new training data between the given curves. Item i of the sequence
    depends only on (seed, i): page with `offset`, or stream any count as .npy with `format` "npy"."""
    runtime = runtime_of(request)
    check_output(req.output, runtime)
    seed = fresh_seed() if req.seed is None else req.seed
    start, stop = req.offset, req.offset + req.count
    spacing = runtime.reading(req.reading()).spacing

    def plan() -> AugmentPlan:
        return runtime.plan_augment(curves, mode=req.mode, seed=seed, neighbours=req.neighbours, reading=req.reading())

    if req.format == "npy":
        return await _stream_augment(request, runtime, plan, req, seed, spacing)

    def work() -> Response:
        made = runtime.augment(plan(), start, stop, n_points=req.n_points, spacing=spacing)
        return JSON(augment_body(made, metrics=req.metrics, output=req.output))

    return await run_inference(request, "/augment", req.count, work)


async def _stream_augment(
    request: Request,
    runtime: CurveRuntime,
    plan: Callable[[], AugmentPlan],
    req: s.AugmentRequest,
    seed: int,
    spacing: str,
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
            return await in_executor(request, fn, *args)
        finally:
            busy += time.perf_counter() - begin

    try:
        planned: AugmentPlan = await in_thread(plan)
        shape = (req.count, runtime.mix_length(planned.prep, req.n_points), 2)
        chunks = runtime.augment_chunks(
            planned, req.offset, req.offset + req.count, n_points=req.n_points, spacing=spacing
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
