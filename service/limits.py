"""The request limits that come from the settings (curves per request, points per curve, …), written once: `BOUNDS`
both checks a request (`check`, a 422 naming the field) and states each limit in the published schema
(`state_bounds`), so a client generated from openapi.yaml knows them. Rules that combine fields (a triplet's steps,
/augment's count by format, refine's work) stay with the routes that own them."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, Protocol

import numpy as np
from pydantic import BaseModel

from curve_vae.inference.errors import InputError

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
