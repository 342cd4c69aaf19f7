"""The Open Inference Protocol (KServe v2, what NVIDIA Triton speaks) over the runtime's own ONNX sessions.

`service/routes/oip.py` serves it under /v2; this module holds what it needs without HTTP:
the models' tensor signatures read from the sessions (`signatures`), the check of a JSON
infer request against them (`parse_request`, raising `OipError` with a message that names the
tensor and what is wrong), the batched run (`infer`) and the per-model request schemas
stated in the OpenAPI document (`describe`).

The tensors are the graphs' raw ones, in the model's plane: encoder `curves` (B, n_points, 2)
→ `mean`, `log_var` (B, latent_dim); decoder `latent` (B, latent_dim) → `curves` (B, n_points, 2)
and, with a B-spline head, `control_points` (B, n_ctrl, 2). None of the REST geometry happens
here (no frames, no resampling, no pose): it is what a Triton server running the export of
`curve-vae triton` computes, so a client can switch between the two by changing the URL.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from typing import Any, Protocol

import numpy as np

from curve_vae.errors import ProtocolError

MODELS = ("encoder", "decoder")
PLATFORM = "onnxruntime_onnx"  # what Triton calls a model served by onnxruntime
#: onnxruntime's tensor types → the protocol's data types
DATATYPES = {
    "tensor(float)": "FP32",
    "tensor(double)": "FP64",
    "tensor(float16)": "FP16",
    "tensor(int64)": "INT64",
    "tensor(int32)": "INT32",
    "tensor(bool)": "BOOL",
}
F32_MAX = float(np.finfo(np.float32).max)
_ABSENT = object()
REQUEST_FIELDS = ("id", "parameters", "inputs", "outputs")
TENSOR_FIELDS = ("name", "shape", "datatype", "data", "parameters")


class OipError(ProtocolError):
    """A request the protocol answers with `{"error": msg}` and `status` (400: bad request, 404: no such model)."""

    def __init__(self, msg: str, status: int = 400) -> None:
        super().__init__(msg)
        self.msg, self.status = msg, status


@dataclass(frozen=True)
class Tensor:
    """One input or output of a graph: shape with -1 for the batch axis (and any other free axis)."""

    name: str
    datatype: str
    shape: tuple[int, ...]

    def json(self) -> dict[str, Any]:
        return {"name": self.name, "datatype": self.datatype, "shape": list(self.shape)}


@dataclass(frozen=True)
class Signature:
    inputs: tuple[Tensor, ...]
    outputs: tuple[Tensor, ...]


class NodeArg(Protocol):
    """What a graph session says of one of its inputs or outputs (onnxruntime's NodeArg)."""

    name: str
    type: str
    shape: list[Any]


class Session(Protocol):
    """The calls this module makes on a graph session (the runtime's onnxruntime sessions answer them): the HTTP layer
    never imports onnxruntime itself."""

    def get_inputs(self) -> list[NodeArg]: ...

    def get_outputs(self) -> list[NodeArg]: ...

    def run(self, output_names: list[str], input_feed: dict[str, np.ndarray]) -> list[Any]: ...


def tensors(args: list[NodeArg]) -> tuple[Tensor, ...]:
    """The protocol's view of an onnxruntime session's inputs or outputs (symbolic axes such as "batch" → -1)."""
    return tuple(
        Tensor(a.name, DATATYPES.get(a.type, a.type), tuple(d if isinstance(d, int) else -1 for d in a.shape))
        for a in args
    )


def signature(session: Session) -> Signature:
    return Signature(tensors(session.get_inputs()), tensors(session.get_outputs()))


def signatures(runtime: Any) -> dict[str, Signature]:
    """Each model's tensors, from the loaded runtime's own sessions."""
    return {"encoder": signature(runtime.graphs.encoder), "decoder": signature(runtime.graphs.decoder)}


def _t(name: str, *shape: int) -> Tensor:
    return Tensor(name, "FP32", shape)


#: The shipped model's tensors: what openapi.yaml states, written without a model loaded (a running server states
#: its own model's, and GET /v2/models/{name} always reads them from the sessions). tests/service/test_oip.py
#: checks these against models/*.onnx.
DEFAULT_SIGNATURES = {
    "encoder": Signature((_t("curves", -1, 161, 2),), (_t("mean", -1, 32), _t("log_var", -1, 32))),
    "decoder": Signature((_t("latent", -1, 32),), (_t("curves", -1, 161, 2), _t("control_points", -1, 31, 2))),
}


# --------------------------------------------------------------------------- requests


@dataclass(frozen=True)
class Request:
    """A checked infer request: one float32 array per graph input, the outputs asked for, the batch size."""

    id: str | None
    feeds: dict[str, np.ndarray]
    outputs: list[str]
    batch: int


def _names(items: tuple[Tensor, ...]) -> str:
    return ", ".join(t.name for t in items)


def _is_int(v: Any) -> bool:
    return isinstance(v, int) and not isinstance(v, bool)


def _numbers(data: Any, where: str, shape: list[int]) -> np.ndarray:
    """The tensor's elements as float64, row-major: a flat list, or nested lists of exactly the tensor's shape."""
    if not isinstance(data, list):
        raise OipError(f"{where}: expected a list of numbers, got {type(data).__name__}")
    flat = data
    if not all(type(v) is float or type(v) is int for v in data):
        if not any(isinstance(v, list) for v in data):
            i, v = next((i, v) for i, v in enumerate(data) if not (type(v) is float or type(v) is int))
            raise OipError(f"{where}[{i}]: {v!r} is not a number")
        flat = []
        stack = [(data, 0)]
        while stack:  # depth first, in order: row-major
            items, depth = stack.pop()
            if len(items) != (shape[depth] if depth < len(shape) else -1):
                raise OipError(f"{where}: nested lists must have the tensor's shape {shape}; flat data is simpler")
            if depth == len(shape) - 1:
                if not all(type(v) is float or type(v) is int for v in items):
                    raise OipError(f"{where}: an innermost list holds something that is not a number")
                flat.extend(items)
            else:
                if not all(isinstance(v, list) for v in items):
                    raise OipError(f"{where}: nested lists must have the tensor's shape {shape}; flat data is simpler")
                stack.extend((v, depth + 1) for v in reversed(items))
    try:
        return np.asarray(flat, dtype=np.float64)
    except OverflowError:  # integers beyond float range
        raise OipError(f"{where}: a number beyond FP32 range") from None


def _check_shape(shape: Any, spec: Tensor, where: str, max_batch: int) -> list[int]:
    if not isinstance(shape, list) or not all(_is_int(d) or (type(d) is float and d.is_integer()) for d in shape):
        raise OipError(f"{where}: expected a list of integers, got {shape!r}")
    shape = [int(d) for d in shape]  # 2.0 is an integer to JSON Schema, and to the protocol's clients
    want = list(spec.shape)
    if len(shape) != len(want) or any(w != -1 and d != w for d, w in zip(shape, want)):
        raise OipError(f"{where}: {shape} does not fit {spec.name}'s shape {want} (-1: any size)")
    if any(d < 1 for d in shape):
        raise OipError(f"{where}: {shape} has an empty or negative axis; every axis needs at least 1")
    if shape[0] > max_batch:
        raise OipError(f"{where}: batch of {shape[0]}; at most {max_batch} per request (CURVE_VAE_MAX_CURVES)")
    return shape


def _check_fields(obj: Any, where: str, allowed: tuple[str, ...], required: tuple[str, ...]) -> dict[str, Any]:
    if not isinstance(obj, dict):
        raise OipError(f"{where}: expected a JSON object with {', '.join(required)}")
    for key in obj:
        if key not in allowed:
            raise OipError(f"{where}.{key}: unknown field (the protocol's are {', '.join(allowed)})")
    for key in required:
        if key not in obj:
            raise OipError(f"{where}.{key}: field required")
    if "parameters" in obj and not isinstance(obj["parameters"], dict):
        raise OipError(f"{where}.parameters: expected a JSON object")
    return obj


def parse_request(body: Any, model: str, sig: Signature, *, max_batch: int) -> Request:
    """Check a decoded JSON infer request against the model's signature; raises OipError naming what is wrong."""
    body = _check_fields(body, "body", REQUEST_FIELDS, ("inputs",))
    rid = body.get("id")
    if "id" in body and not isinstance(rid, str):
        raise OipError(f"id: expected a string, got {json.dumps(rid)}")
    inputs = body["inputs"]
    if not isinstance(inputs, list) or not inputs:
        raise OipError(f"inputs: expected a list of tensors ({model}'s: {_names(sig.inputs)})")
    specs = {t.name: t for t in sig.inputs}
    feeds: dict[str, np.ndarray] = {}
    for i, item in enumerate(inputs):
        where = f"inputs[{i}]"
        t = _check_fields(item, where, TENSOR_FIELDS, ("name", "shape", "datatype", "data"))
        name = t["name"]
        if not isinstance(name, str):
            raise OipError(f"{where}.name: expected a string, got {json.dumps(name)}")
        if name not in specs:
            known = _names(sig.inputs)
            raise OipError(f"{where}.name: unknown input tensor {name!r}; the {model}'s inputs are {known}")
        if name in feeds:
            raise OipError(f"{where}.name: input {name!r} given twice")
        spec = specs[name]
        if t["datatype"] != spec.datatype:
            raise OipError(f"{where}.datatype: {json.dumps(t['datatype'])}, but {name} is {spec.datatype}")
        shape = _check_shape(t["shape"], spec, f"{where}.shape", max_batch)
        values = _numbers(t["data"], f"{where}.data", shape)
        size = math.prod(shape)
        if len(values) != size:
            raise OipError(f"{where}.data: {len(values)} numbers, but shape {shape} holds {size}")
        out_of_range = ~(np.abs(values) <= F32_MAX)  # NaN too
        if out_of_range.any():
            j = int(np.argmax(out_of_range))
            raise OipError(f"{where}.data[{j}]: {float(values[j])!r} is not a finite FP32 number")
        feeds[name] = values.astype(np.float32).reshape(shape)
    missing = [t.name for t in sig.inputs if t.name not in feeds]
    if missing:
        raise OipError(f"inputs: {', '.join(missing)} missing; the {model}'s inputs are {_names(sig.inputs)}")
    batches = {a.shape[0] for a in feeds.values()}
    if len(batches) > 1:
        raise OipError(f"inputs: batch sizes differ ({sorted(batches)}); the first axis is the batch")
    outputs = _requested_outputs(body.get("outputs", _ABSENT), model, sig)
    return Request(rid, feeds, outputs, batches.pop())


def _requested_outputs(requested: Any, model: str, sig: Signature) -> list[str]:
    """The outputs asked for, in the order asked, each once; none asked for: all of them."""
    known = [t.name for t in sig.outputs]
    if requested is _ABSENT:
        return known
    if not isinstance(requested, list):
        raise OipError('outputs: expected a list of {"name": ...}')
    names: list[str] = []
    for i, item in enumerate(requested):
        name = _check_fields(item, f"outputs[{i}]", ("name", "parameters"), ("name",))["name"]
        if not isinstance(name, str):
            raise OipError(f"outputs[{i}].name: expected a string, got {json.dumps(name)}")
        if name not in known:
            raise OipError(
                f"outputs[{i}].name: unknown output tensor {name!r}; the {model}'s outputs are {_names(sig.outputs)}"
            )
        if name not in names:
            names.append(name)
    return names or known


def infer(session: Session, req: Request, *, batch_size: int) -> dict[str, np.ndarray]:
    """Run the graph on the request in runs of `batch_size` rows; raises OipError where an output is not finite."""
    parts: list[list[np.ndarray]] = [[] for _ in req.outputs]
    for start in range(0, req.batch, batch_size):
        feed = {k: v[start : start + batch_size] for k, v in req.feeds.items()}
        for part, out in zip(parts, session.run(req.outputs, feed)):
            part.append(out)
    result = {name: np.concatenate(p) for name, p in zip(req.outputs, parts)}
    for name, a in result.items():
        bad = ~np.isfinite(a).reshape(len(a), -1).all(axis=1)
        if bad.any():
            raise OipError(
                f"outputs: {name} is not finite for batch row {int(np.argmax(bad))}: its input lies far outside "
                "the model's plane (the REST routes bring curves there; these tensors are taken as they are)"
            )
    return result


def response(model: str, version: str, req: Request, result: dict[str, np.ndarray]) -> dict[str, Any]:
    """The protocol's infer response: each output flattened row-major, with its shape."""
    body: dict[str, Any] = {"model_name": model, "model_version": version}
    if req.id is not None:
        body["id"] = req.id
    body["outputs"] = [
        {"name": name, "datatype": "FP32", "shape": list(a.shape), "data": a.ravel().tolist()}
        for name, a in result.items()
    ]
    return body


def metadata(model: str, version: str, sig: Signature) -> dict[str, Any]:
    return {
        "name": model,
        "versions": [version],
        "platform": PLATFORM,
        "inputs": [t.json() for t in sig.inputs],
        "outputs": [t.json() for t in sig.outputs],
    }


# --------------------------------------------------------------------------- the OpenAPI document
