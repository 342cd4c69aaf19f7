"""Each endpoint as a call: the request it sends (a JSON body, or the curves as a .npy body with the other fields in
the query) and how its answer becomes a result object. `Client` and `AsyncClient` send the same calls."""

from __future__ import annotations

import io
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Any

import numpy as np
import orjson

from curve_vae.client.design import BSplineFit, Fitted, Revolved
from curve_vae.client.results import (
    Augmented,
    Closeness,
    Curves,
    Encoded,
    Interpolated,
    ModelRef,
    Reconstructed,
    Sampled,
    bools,
    curve_list,
)
from curve_vae.inference.choices import FrameMode, Pose, Spacing

NPY = "application/x-npy"
JSON_OPTIONS = orjson.OPT_SERIALIZE_NUMPY

Headers = Mapping[str, str]
NO_HEADERS: Headers = MappingProxyType({})


@dataclass(frozen=True)
class Call:
    """One HTTP request and the parser of its answer (response body, the model that answered, the response's
    headers -> result)."""

    method: str
    path: str
    parse: Callable[[bytes, ModelRef, Headers], Any]
    json: Any = None
    content: bytes | None = None
    params: dict[str, str] = field(default_factory=dict)
    content_type: str = "application/json"

    def body(self) -> bytes | None:
        if self.content is not None:
            return self.content
        return None if self.json is None else orjson.dumps(self.json, option=JSON_OPTIONS)


def array(values: Any) -> np.ndarray:
    """float64 in C order, which orjson writes directly: a caller's slice or reversed view (curve[::-1]) included."""
    return np.ascontiguousarray(values, dtype=np.float64)


def _fields(**kw: Any) -> dict[str, Any]:
    """The fields a call was given (None: the service's default)."""
    return {k: v for k, v in kw.items() if v is not None}


def curves_call(
    path: str, curves: Sequence[Any], fields: dict[str, Any], parse: Callable[..., Any], *, npy_points: int
) -> Call:
    """The curves as a .npy body when they share a length and hold at least `npy_points` points in all (no JSON
    to write or parse), else as JSON."""
    arrays = [array(c) for c in curves]
    same = bool(arrays) and all(a.shape == arrays[0].shape and a.ndim == 2 for a in arrays)
    if same and sum(len(a) for a in arrays) >= npy_points:
        buf = io.BytesIO()
        np.save(buf, np.stack(arrays), allow_pickle=False)
        params = {
            k: v if isinstance(v, str) else orjson.dumps(v, option=JSON_OPTIONS).decode() for k, v in fields.items()
        }
        return Call("POST", path, parse, content=buf.getvalue(), params=params, content_type=NPY)
    return Call("POST", path, parse, json={"curves": arrays, **fields})


def _load(body: bytes) -> dict[str, Any]:
    return orjson.loads(body)


def parse_encoded(body: bytes, model: ModelRef, _headers: Headers = NO_HEADERS) -> Encoded:
    d = _load(body)
    return Encoded(
        model,
        np.asarray(d["mean"], np.float64),
        np.asarray(d["log_var"], np.float64),
        d.get("frames"),
        closeness=Closeness.parse(d.get("closeness")),
    )


def _curves_part(d: dict[str, Any]) -> dict[str, Any]:
    return {"curves": curve_list(d.get("curves")), "splines": d.get("splines"), "metrics": d.get("metrics")}


def parse_curves(body: bytes, model: ModelRef, _headers: Headers = NO_HEADERS) -> Curves:
    return Curves(model, **_curves_part(_load(body)))


def parse_reconstructed(body: bytes, model: ModelRef, _headers: Headers = NO_HEADERS) -> Reconstructed:
    d = _load(body)
    return Reconstructed(
        model,
        **_curves_part(d),
        mse=np.asarray(d["mse"], np.float64),
        closeness=Closeness.parse(d.get("closeness")),
        repaired=bools(d.get("repaired")),
    )


def parse_interpolated(body: bytes, model: ModelRef, _headers: Headers = NO_HEADERS) -> Interpolated:
    d = _load(body)
    return Interpolated(
        model,
        **_curves_part(d),
        weights=np.asarray(d["weights"], np.float64),
        frames=d.get("frames"),
        valid=bools(d.get("valid")),
        repaired=bools(d.get("repaired")),
        ends=Closeness.parse(d.get("ends")),
    )


def parse_sampled(body: bytes, model: ModelRef, _headers: Headers = NO_HEADERS) -> Sampled:
    d = _load(body)
    return Sampled(
        model,
        **_curves_part(d),
        latents=np.asarray(d["latents"], np.float64),
        seed=int(d["seed"]),
        prior=str(d["prior"]),
        rejected=int(d["rejected"]),
        invalid=int(d["invalid"]),
    )


def parse_augmented(body: bytes, model: ModelRef, _headers: Headers = NO_HEADERS) -> Augmented:
    d = _load(body)
    return Augmented(
        model,
        **_curves_part(d),
        sources=np.asarray(d["sources"], np.int64),
        weights=np.asarray(d["weights"], np.float64),
        frames=d.get("frames"),
        seed=int(d["seed"]),
        offset=int(d["offset"]),
        redrawn=_count(d.get("redrawn")),
        invalid=_count(d.get("invalid")),
    )


def _count(value: Any) -> int | None:
    return None if value is None else int(value)


def parse_fitted(body: bytes, model: ModelRef, _headers: Headers = NO_HEADERS) -> Fitted:
    return Fitted(model, [BSplineFit.from_json(f) for f in _load(body)["fits"]])


def parse_npy(body: bytes, _model: ModelRef, _headers: Headers = NO_HEADERS) -> np.ndarray:
    return np.load(io.BytesIO(body), allow_pickle=False)


def parse_json(body: bytes, _model: ModelRef, _headers: Headers = NO_HEADERS) -> Any:
    return _load(body)


# ------------------------------------------------------------------------------------------ the endpoints


def reading(
    frame: FrameMode | None, pose: Pose | None, spacing: Spacing | None, looks: int | None, refine: int | None
) -> dict[str, Any]:
    """The reading's fields the caller set (inference.reading.Reading's options; the server's defaults for the rest)."""
    return _fields(frame=frame, pose=pose, spacing=spacing, looks=looks, refine=refine)


def output(n_points: int | None, output_as: str | None, metrics: bool | None) -> dict[str, Any]:
    return _fields(n_points=n_points, output=output_as, metrics=metrics)


def decode_call(latents: Any, fields: dict[str, Any]) -> Call:
    return Call("POST", "/decode", parse_curves, json={"latents": array(latents), **fields})


def sample_call(count: int, fields: dict[str, Any]) -> Call:
    return Call("POST", "/sample", parse_sampled, json={"count": count, **fields})


def augment_call(curves: Sequence[Any], fields: dict[str, Any], *, npy: bool) -> Call:
    body = {"curves": [array(c) for c in curves], **fields, **({"format": "npy"} if npy else {})}
    return Call("POST", "/augment", parse_npy if npy else parse_augmented, json=body)


def fit_call(curves: Sequence[Any], fields: dict[str, Any]) -> Call:
    return Call("POST", "/fit", parse_fitted, json={"curves": [array(c) for c in curves], **fields})


def revolve_call(curve: Any, fields: dict[str, Any]) -> Call:
    asked = str(fields.get("format", "obj"))  # the service's default format

    def parse(body: bytes, model: ModelRef, headers: Headers = NO_HEADERS) -> Revolved:
        return Revolved.from_answer(model, body, headers, asked)

    return Call("POST", "/revolve", parse, json={"curve": array(curve), **fields})
