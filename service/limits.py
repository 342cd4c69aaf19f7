"""The request limits, written once. Those that come from the settings (curves per request, points per curve, …) are
`BOUNDS`: it both checks a request (`check`, a 422 naming the field) and states each limit in the published schema
(`state_bounds`), so a client generated from openapi.yaml knows them. The rules that combine fields are here too:
refine's work (`check_refine`), an interpolation's weights and grid (`check_weights`), /augment's count and body by
format (`check_augment_format`), a revolved mesh's triangles (`check_mesh`); `check_request` applies all that apply
(service.routing builds every route with it). A schema's own bounds (≥ 4 points, refine's 0…MAX_REFINE_STEPS from
the reading's definition, inference.choices) are the request models'."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, Protocol

import numpy as np
from pydantic import BaseModel

from curve_vae.geometry import simplex_grid, simplex_grid_size
from curve_vae.inference.errors import InputError
from curve_vae.inference.reading import Reading
from curve_vae.inference.runtime import CurveRuntime
from curve_vae.service.schemas import AugmentRequest, InterpolateRequest, RevolveRequest

DEFAULT_STEPS = 5  # the paper interpolates in five steps (§4)
WEIGHT_SUM_TOLERANCE = 1e-6

#: openapi.yaml's latent length (the shipped model's); the live schema states the loaded model's.
DEFAULT_LATENT_DIM = 32


@dataclass(frozen=True)
class Bound:
    """A field of a request model bounded by a setting: its length (`items`), each item's length (`per_item`), or
    its value (`value`)."""

    setting: str  # the Settings field (and CURVE_VAE_ variable) that holds the limit
    model: str  # the request model's class name
    field: str
    kind: str  # "items" | "per_item" | "value"
    noun: str = ""  # what is counted, for the message ("curves per request")
    checked: bool = True  # False: stated in the schema, checked by the route with what it combines


CURVE_REQUESTS = ("EncodeRequest", "ReconstructRequest", "InterpolateRequest", "AugmentRequest", "FitRequest")
N_POINTS = (
    "DecodeRequest",
    "ReconstructRequest",
    "InterpolateRequest",
    "SampleRequest",
    "AugmentRequest",
    "FitRequest",
)

BOUNDS: tuple[Bound, ...] = (
    *(Bound("max_curves", m, "curves", "items", "curves per request") for m in CURVE_REQUESTS),
    *(Bound("max_points", m, "curves", "per_item", "points per curve") for m in CURVE_REQUESTS),
    Bound("max_points", "RevolveRequest", "curve", "items", "points"),
    *(Bound("max_points", m, "n_points", "value") for m in N_POINTS),
    Bound("max_curves", "DecodeRequest", "latents", "items", "latents per request"),
    Bound("max_curves", "DecodeRequest", "frames", "items", "frames per request"),
    Bound("max_curves", "SampleRequest", "count", "value"),
    Bound("max_curves", "InterpolateRequest", "steps", "value", checked=False),  # and the grid it makes: deps
    Bound("max_curves", "InterpolateRequest", "weights", "items", "rows"),
)


def _message(bound: Bound, limit: int, got: int) -> str:
    return f"at most {limit} {bound.noun}, got {got}" if bound.noun else f"at most {limit}, got {got}"


def check(req: BaseModel, settings: Any, *, skip: tuple[str, ...] = ()) -> None:
    """InputError for the first bound `req` breaks (its model's BOUNDS; fields in `skip` are checked elsewhere)."""
    name = type(req).__name__
    for bound in BOUNDS:
        if bound.model != name or bound.field in skip or not bound.checked:
            continue
        value = getattr(req, bound.field, None)
        if value is None:
            continue
        limit = int(getattr(settings, bound.setting))
        if bound.kind == "items" and len(value) > limit:
            raise InputError((bound.field,), _message(bound, limit, len(value)))
        if bound.kind == "per_item":
            for i, item in enumerate(value):
                if len(item) > limit:
                    raise InputError((bound.field, i), _message(bound, limit, len(item)))
        if bound.kind == "value" and value > limit:
            raise InputError((bound.field,), _message(bound, limit, value))


def check_request(req: BaseModel, settings: Any, curves: list[np.ndarray], *, skip: tuple[str, ...] = ()) -> None:
    """Every limit a request is held to, in one place (service.routing.model_route calls it for every route): its
    model's BOUNDS, refine's work for a request that reads curves, /augment's count and body by format."""
    check(req, settings, skip=skip)
    reading = getattr(req, "reading", None)
    if reading is not None:
        check_refine(reading(), curves, settings)
    if isinstance(req, AugmentRequest):
        check_augment_format(req, settings)
    if isinstance(req, RevolveRequest):
        check_mesh(req, settings)


def check_mesh(req: RevolveRequest, settings: Any) -> None:
    """The triangles a revolved profile can make, 2 × (points - 1) × segments, within CURVE_VAE_MAX_MESH_TRIANGLES."""
    triangles = 2 * (len(req.curve) - 1) * req.segments  # at most: pole bands have half as many
    if triangles > settings.max_mesh_triangles:
        raise InputError(
            ("segments",),
            f"{req.segments} segments of a {len(req.curve)}-point profile make up to {triangles} triangles; at most "
            f"{settings.max_mesh_triangles} (CURVE_VAE_MAX_MESH_TRIANGLES)",
        )


def check_shape(model: str, count: int, points: int, settings: Any) -> None:
    """The curve bounds of `model` for curves given as one array (count, points, 2): a .npy body."""
    for bound in BOUNDS:
        if bound.model == model and bound.field == "curves":
            limit = int(getattr(settings, bound.setting))
            got = count if bound.kind == "items" else points
            if got > limit:
                raise InputError(("curves",), _message(bound, limit, got))


class WithCurves(Protocol):
    """A request that carries curves (`curves`: a list of curves of [x, y] points)."""

    @property
    def curves(self) -> Sequence[Any]: ...


def curves_of(req: WithCurves) -> list[np.ndarray]:
    """A checked request's curves as float64 arrays."""
    return [np.asarray(c, dtype=np.float64) for c in req.curves]


#: What one curve costs a fitting step beyond its points, in points: its decoder runs (inference/fitting.py) take
#: about as long as matching 300 points (10 steps: ~86 ms for a 4-point curve, ~130 ms for a 161-point one).
REFINE_POINTS_PER_CURVE = 300
#: What one curve costs a look again (inference/looking.py), in the same points: one encoder and one decoder row and a
#: placement, ~2.1–2.5 ms a curve of 8 to 1,000 points where a refine step of a 161-point curve costs ~2.0 ms beyond
#: its first (the Jacobian's) and 300 + 161 points of work.
LOOK_POINTS_PER_CURVE = 80


def check_refine(reading: Reading, curves: list[np.ndarray], settings: Any) -> None:
    """The fitting work a request asks for — refine × (input points + REFINE_POINTS_PER_CURVE per curve) + looks ×
    LOOK_POINTS_PER_CURVE per curve — within CURVE_VAE_MAX_REFINE_WORK; the field named is refine where it asks for
    steps, else looks."""
    points = sum(len(c) for c in curves)
    fitting = reading.refine * (points + REFINE_POINTS_PER_CURVE * len(curves))
    work = fitting + reading.looks * LOOK_POINTS_PER_CURVE * len(curves)
    if work > settings.max_refine_work:
        field = "refine" if reading.refine else "looks"
        raise InputError(
            (field,),
            f"refine {reading.refine} and looks {reading.looks} on {len(curves)} curves of {points} points in all "
            f"are {work} units of work (refine × (points + {REFINE_POINTS_PER_CURVE} per curve) + looks × "
            f"{LOOK_POINTS_PER_CURVE} per curve); at most {settings.max_refine_work} (CURVE_VAE_MAX_REFINE_WORK): "
            "send fewer curves, steps or looks",
        )


def check_weights(req: InterpolateRequest, settings: Any) -> np.ndarray:
    """The weight rows of an interpolation: the even grid of `steps` (default DEFAULT_STEPS) within max_curves, or
    the request's rows, one number per curve, each summing to 1."""
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


def check_augment_format(req: AugmentRequest, settings: Any) -> None:
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


def state_bounds(schema: dict[str, Any], settings: Any, latent_dim: int | None) -> dict[str, Any]:
    """Write BOUNDS into the app's schema (maxItems, items' maxItems, maximum), and what the model fixes: the
    latent length; and that steps and weights exclude each other."""
    comps = schema.get("components", {}).get("schemas", {})

    def prop(model: str, field: str) -> dict[str, Any]:
        return _field_schema(comps, model, field)

    for bound in BOUNDS:
        if bound.model not in comps:
            continue
        p, limit = prop(bound.model, bound.field), int(getattr(settings, bound.setting))
        if bound.kind == "items":
            p["maxItems"] = limit
        elif bound.kind == "per_item":
            p["items"]["maxItems"] = limit
        else:
            p["maximum"] = limit
    if "AugmentRequest" in comps:  # format npy streams up to max_stream_curves (the route checks json's max_curves)
        prop("AugmentRequest", "count")["maximum"] = max(settings.max_curves, settings.max_stream_curves)
    if "DecodeRequest" in comps:
        dim = latent_dim or DEFAULT_LATENT_DIM
        prop("DecodeRequest", "latents")["items"].update(minItems=dim, maxItems=dim)
    if "InterpolateRequest" in comps:
        comps["InterpolateRequest"]["not"] = {"required": ["steps", "weights"]}
    return schema


def name_priors(schema: dict[str, Any], names: list[str]) -> dict[str, Any]:
    """/sample's `prior`: the names this server's model and priors folder offer, as the schema's enum."""
    comps = schema.get("components", {}).get("schemas", {})
    if "SampleRequest" in comps:
        _field_schema(comps, "SampleRequest", "prior")["enum"] = list(names)
    return schema


def _field_schema(comps: dict[str, Any], model: str, field: str) -> dict[str, Any]:
    """A request field's schema; for `X | None` fields its non-null branch, where bounds and choices go."""
    p = comps[model]["properties"][field]
    return next((b for b in p.get("anyOf", []) if b.get("type") != "null"), p)


def check_output(output: str, runtime: CurveRuntime) -> None:
    """A spline output needs a model with a B-spline head."""
    if output != "points" and not runtime.has_splines:
        raise InputError(
            ("output",),
            f'"{output}" needs a model with a B-spline head, and this one has none (GET /model: spline is null); '
            'ask for "points", or fit splines to the points with /fit',
        )
