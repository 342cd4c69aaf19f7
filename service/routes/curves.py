"""The model's routes: encode, decode, reconstruct, interpolate, sample, augment. Each validates, calls the
runtime in a worker thread (deps.run_inference) and shapes the JSON.

Length (~450 lines): six routes, each ~20 lines of work and ~40 of OpenAPI examples beside the
route they document, with their .npy bodies and /augment's format checks and .npy stream beside
them; one router per resource, as FastAPI's bigger-applications layout has it."""

from __future__ import annotations

import time
from collections.abc import AsyncIterator, Callable
from typing import Annotated, Any

import numpy as np
from fastapi import APIRouter, Body, Request
from fastapi.responses import Response, StreamingResponse

from curve_vae.inference.augmenting import AugmentPlan
from curve_vae.inference.bodies import augment_body, frames_json, sample_body, with_metrics, with_output
from curve_vae.inference.errors import InputError
from curve_vae.inference.npy import MEDIA_TYPE as NPY_MEDIA_TYPE
from curve_vae.inference.npy import chunk_bytes, npy_header, npy_size
from curve_vae.inference.runtime import CurveRuntime
from curve_vae.inference.sampling import fresh_seed
from curve_vae.service import schemas as s
from curve_vae.service.api_docs import C1, C2, C3, POST_ERRORS, curl_sample, example
from curve_vae.service.deps import (
    RuntimeDep,
    SettingsDep,
    check_curves,
    check_n_points,
    check_refine,
    check_weights,
    in_executor,
    run_inference,
    runtime_of,
    settings_of,
    splines_wanted,
)
from curve_vae.service.fastjson import JSON, FastJSONRoute
from curve_vae.service.metrics import Metrics
from curve_vae.service.npy_bodies import OPENAPI_BODY as NPY_BODY
from curve_vae.service.npy_bodies import npy_route
from curve_vae.service.settings import Settings

ONE_CURVE = '{"curves": [[[0,0],[1,2],[2.5,3.2],[4,3.5],[5.5,3],[7,1.5],[8,0]]]}'
curves_router = APIRouter(route_class=FastJSONRoute, tags=["curves"])


@curves_router.post(
    "/encode",
    response_model=s.EncodeResponse,
    responses=POST_ERRORS,
    summary="Latent mean and log-variance of each curve",
    openapi_extra=NPY_BODY
    | curl_sample("/encode", '{"curves": [[[0,0],[1,2],[2.5,3.2],[4,3.5],[5.5,3],[7,1.5],[8,0]]]}'),
)
async def encode(
    request: Request,
    runtime: RuntimeDep,
    settings: SettingsDep,
    req: Annotated[
        s.EncodeRequest,
        Body(
            openapi_examples={
                "one curve": example("A curve in its own frame", {"curves": [C1]}),
                "model frame": example(
                    "Already in the 128×128 plane",
                    {"curves": [[[14, 64], [40, 100], [64, 110], [90, 95], [114, 64]]], "frame": "model"},
                ),
            }
        ),
    ],
) -> Response:
    """Encode curves (any frame, any length ≥ 4) into the latent space (the encoder's mean and log-variance).
    The curves may also be posted as a .npy body (`Content-Type: application/x-npy`), the other fields in the query."""
    return await _encode(request, req, check_curves(req.curves, settings))


def _taken(req: s.EncodeRequest | s.ReconstructRequest | s.InterpolateRequest) -> dict[str, Any]:
    """How a request's curves are brought to the model: the runtime's frame, spacing, pose and refine options."""
    return {"frame": req.frame, "spacing": req.spacing, "pose": req.pose, "refine": req.refine}


@npy_route("/encode", s.EncodeRequest)
async def _encode(request: Request, req: s.EncodeRequest, curves: list[np.ndarray]) -> Response:
    runtime = runtime_of(request)
    check_refine(req.refine, curves, settings_of(request))

    def work() -> Response:
        mean, log_var, frames = runtime.encode(curves, **_taken(req))
        # float64 as the JSON always carried: orjson would write float32 at float32's shorter precision
        return JSON(
            {"mean": mean.astype(np.float64), "log_var": log_var.astype(np.float64), "frames": frames_json(frames)}
        )

    return await run_inference(request, "/encode", len(curves), work)


@curves_router.post(
    "/decode",
    response_model=s.CurvesResponse,
    responses=POST_ERRORS,
    summary="Curves for latent vectors",
    openapi_extra=curl_sample("/decode", '{"latents": [[' + ",".join(["0"] * 32) + ']], "n_points": 50}'),
)
async def decode(
    request: Request,
    runtime: RuntimeDep,
    settings: SettingsDep,
    req: Annotated[
        s.DecodeRequest,
        Body(
            openapi_examples={
                "origin": example(
                    "The centre of the latent space, 50 points", {"latents": [[0.0] * 32], "n_points": 50}
                ),
                "in a frame": example(
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
    check_n_points(req.n_points, settings)
    frames = [f.frame() for f in req.frames] if req.frames else None

    splines = splines_wanted(req.output, runtime)

    def work() -> Response:
        latents = np.array(req.latents, np.float64)
        curves = runtime.decode(latents, n_points=req.n_points, spacing=req.spacing, frames=frames, splines=splines)
        return JSON(with_output(with_metrics({"curves": curves.tolist()}, curves, req.metrics), splines, req.output))

    return await run_inference(request, "/decode", len(req.latents), work)


@curves_router.post(
    "/reconstruct",
    response_model=s.ReconstructResponse,
    responses=POST_ERRORS,
    summary="Pass curves through the VAE",
    openapi_extra=NPY_BODY
    | curl_sample("/reconstruct", '{"curves": [[[0,0],[1,2],[2.5,3.2],[4,3.5],[5.5,3],[7,1.5],[8,0]]]}'),
)
async def reconstruct(
    request: Request,
    runtime: RuntimeDep,
    settings: SettingsDep,
    req: Annotated[
        s.ReconstructRequest,
        Body(
            openapi_examples={
                "one curve": example("A curve in its own frame, back at its own 7 points", {"curves": [C1]}),
                "resampled": example("Two curves, returned at 100 points each", {"curves": [C1, C2], "n_points": 100}),
                "points and spline": example(
                    "The reconstruction as points and as the B-spline they lie on", {"curves": [C1], "output": "both"}
                ),
            }
        ),
    ],
) -> Response:
    """Encode each curve's latent mean and decode it: the reconstruction in the caller's frame, and its MSE there.
    The curves may also be posted as a .npy body (`Content-Type: application/x-npy`), the other fields in the query."""
    return await _reconstruct(request, req, check_curves(req.curves, settings))


@npy_route("/reconstruct", s.ReconstructRequest)
async def _reconstruct(request: Request, req: s.ReconstructRequest, curves: list[np.ndarray]) -> Response:
    runtime, settings = runtime_of(request), settings_of(request)
    check_n_points(req.n_points, settings)
    check_refine(req.refine, curves, settings)
    splines = splines_wanted(req.output, runtime)

    def work() -> Response:
        out, mse = runtime.reconstruct(curves, n_points=req.n_points, splines=splines, **_taken(req))
        body = with_metrics({"curves": [np.ascontiguousarray(c) for c in out], "mse": mse}, out, req.metrics)
        return JSON(with_output(body, splines, req.output))

    return await run_inference(request, "/reconstruct", len(curves), work)


@curves_router.post(
    "/interpolate",
    response_model=s.InterpolateResponse,
    responses=POST_ERRORS,
    summary="Curves between curves, by mixing latent means",
    openapi_extra=NPY_BODY
    | curl_sample(
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
                "pair": example(
                    "Pair, 5 curves from the first to the second (paper eq. 9)", {"curves": [C1, C2], "steps": 5}
                ),
                "triplet": example(
                    "Triplet, barycentric grid of 6 curves (paper eq. 10)", {"curves": [C1, C2, C3], "steps": 3}
                ),
                "weights": example(
                    "Explicit weights, one entry per curve", {"curves": [C1, C2], "weights": [[0.25, 0.75]]}
                ),
                "as B-splines": example(
                    "The middle curve as a B-spline: control points, knots, degree and the parameter of each point",
                    {"curves": [C1, C2], "weights": [[0.5, 0.5]], "output": "bspline"},
                ),
            }
        ),
    ],
) -> Response:
    """Decode affine combinations of the curves' latent means; with frame "auto" each result is mapped
    into the same blend of the inputs' frames. The curves may also be posted as a .npy body
    (`Content-Type: application/x-npy`), the other fields in the query."""
    return await _interpolate(request, req, check_curves(req.curves, settings))


@npy_route("/interpolate", s.InterpolateRequest)
async def _interpolate(request: Request, req: s.InterpolateRequest, curves: list[np.ndarray]) -> Response:
    runtime, settings = runtime_of(request), settings_of(request)
    check_n_points(req.n_points, settings)
    check_refine(req.refine, curves, settings)
    weights = check_weights(req, settings)
    splines = splines_wanted(req.output, runtime)

    def work() -> Response:
        out, frames = runtime.interpolate(curves, weights, n_points=req.n_points, splines=splines, **_taken(req))
        body = {"weights": weights, "curves": np.ascontiguousarray(out), "frames": frames_json(frames)}
        return JSON(with_output(with_metrics(body, out, req.metrics), splines, req.output))

    return await run_inference(request, "/interpolate", len(weights), work)


@curves_router.post(
    "/sample",
    response_model=s.SampleResponse,
    responses=POST_ERRORS,
    summary="New curves from the learned latent distribution (or the standard prior)",
    openapi_extra=curl_sample("/sample", '{"count": 3, "seed": 7, "n_points": 50}'),
)
async def sample(
    request: Request,
    runtime: RuntimeDep,
    settings: SettingsDep,
    req: Annotated[
        s.SampleRequest,
        Body(
            openapi_examples={
                "seeded": example("Three curves, reproducible", {"count": 3, "seed": 7, "n_points": 50}),
                "tame": example("Closer to typical shapes", {"count": 2, "seed": 1, "temperature": 0.5}),
                "standard prior": example(
                    "The VAE's N(0, I), every draw kept", {"count": 2, "seed": 1, "prior": "standard", "valid": False}
                ),
                "framed": example(
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
    check_n_points(req.n_points, settings)
    seed = fresh_seed() if req.seed is None else req.seed
    frame = req.frame.frame() if req.frame else None

    splines = splines_wanted(req.output, runtime)

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
        return JSON(with_output(sample_body(made, seed, metrics=req.metrics), splines, req.output))

    return await run_inference(request, "/sample", req.count, work)


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


@curves_router.post(
    "/augment",
    response_model=s.AugmentResponse,
    responses={200: AUGMENT_NPY, **POST_ERRORS},
    summary="New curves between given curves",
    openapi_extra=curl_sample(
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
                "pairs": example("Four random pair interpolants", {"curves": [C1, C2, C3], "count": 4, "seed": 1}),
                "triplets": example(
                    "Two random triplet interpolants", {"curves": [C1, C2, C3], "count": 2, "mode": "triplet"}
                ),
                "neighbours, second page": example(
                    "Pairs of near neighbours only; curves 4 and 5 of the seeded sequence",
                    {"curves": [C1, C2, C3], "count": 2, "neighbours": 1, "seed": 1, "offset": 4},
                ),
                "npy": example(
                    "1000 curves as a binary .npy file (curl -o batch.npy)",
                    {"curves": [C1, C2, C3], "count": 1000, "seed": 1, "n_points": 64, "format": "npy"},
                ),
            }
        ),
    ],
) -> Response:
    """Random interpolants of random pairs or triplets of the curves (optionally near neighbours in latent space),
    each in the blend of its sources' frames: new training data between the given curves. Item i of the sequence
    depends only on (seed, i): page with `offset`, or stream any count as .npy with `format` "npy"."""
    curves = check_curves(req.curves, settings)
    _check_augment_format(req, settings)
    splines = splines_wanted(req.output, runtime)
    check_n_points(req.n_points, settings)
    seed = fresh_seed() if req.seed is None else req.seed
    start, stop = req.offset, req.offset + req.count

    def plan() -> AugmentPlan:
        return runtime.plan_augment(
            curves,
            mode=req.mode,
            seed=seed,
            neighbours=req.neighbours,
            frame=req.frame,
            spacing=req.spacing,
            pose=req.pose,
        )

    if req.format == "npy":
        return await _stream_augment(request, runtime, plan, req, seed)

    def work() -> Response:
        out, sources, weights, frames = runtime.augment_batch(
            plan(), start, stop, n_points=req.n_points, spacing=req.spacing, splines=splines
        )
        body = augment_body(out, sources, weights, frames, seed=seed, offset=req.offset, metrics=req.metrics)
        return JSON(with_output(body, splines, req.output))

    return await run_inference(request, "/augment", req.count, work)


def _check_augment_format(req: s.AugmentRequest, settings: Settings) -> None:
    """What the body's format allows: the count (a page of JSON, or a stream of .npy) and what a .npy body can carry."""
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
            return await in_executor(request, fn, *args)
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
