"""The Open Inference Protocol's per-model request schemas in the OpenAPI document, read from the same tensor
signatures that service.oip checks requests against."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from curve_vae.service.oip import F32_MAX, Signature, Tensor


def _shape_schema(t: Tensor, max_batch: int) -> dict[str, Any]:
    axes: list[dict[str, Any]] = [
        {"type": "integer", "minimum": 1, "maximum": max_batch}
        if i == 0
        else ({"type": "integer", "minimum": 1} if d == -1 else {"type": "integer", "const": d})
        for i, d in enumerate(t.shape)
    ]
    return {
        "type": "array",
        "prefixItems": axes,
        "minItems": len(axes),
        "maxItems": len(axes),
        "description": f"{list(t.shape)} with the batch size for -1 (1 to {max_batch}, CURVE_VAE_MAX_CURVES).",
    }


def _input_schema(t: Tensor, max_batch: int) -> dict[str, Any]:
    row = math.prod(d for d in t.shape[1:] if d != -1)
    return {
        "type": "object",
        "title": f"{t.name} tensor",
        "additionalProperties": False,
        "required": ["name", "shape", "datatype", "data"],
        "properties": {
            "name": {"type": "string", "enum": [t.name]},
            "shape": _shape_schema(t, max_batch),
            "datatype": {"type": "string", "enum": [t.datatype]},
            "data": {
                "type": "array",
                "items": {"type": "number", "minimum": -F32_MAX, "maximum": F32_MAX},
                "minItems": row,
                "maxItems": row * max_batch,
                "description": "The elements, flattened row-major: exactly the product of `shape` numbers. "
                "(Nested lists of the tensor's shape are accepted too, as the protocol allows.)",
            },
            "parameters": {"type": "object", "description": "Ignored."},
        },
    }


def request_schema(model: str, sig: Signature, max_batch: int) -> dict[str, Any]:
    """The JSON schema of an infer request to `model`: its tensor names, datatypes and fixed axes."""
    return {
        "type": "object",
        "title": f"{model} infer request",
        "additionalProperties": False,
        "required": ["inputs"],
        "properties": {
            "id": {"type": "string", "description": "Echoed in the response."},
            "parameters": {"type": "object", "description": "Ignored."},
            "inputs": {
                "type": "array",
                "items": (
                    _input_schema(sig.inputs[0], max_batch)
                    if len(sig.inputs) == 1
                    else {"anyOf": [_input_schema(t, max_batch) for t in sig.inputs]}
                ),
                "minItems": len(sig.inputs),
                "maxItems": len(sig.inputs),
            },
            "outputs": {
                "type": "array",
                "description": "The outputs to return, in this order (each once); absent or empty: all.",
                "items": {
                    "type": "object",
                    "additionalProperties": False,
                    "required": ["name"],
                    "properties": {
                        "name": {"type": "string", "enum": [t.name for t in sig.outputs]},
                        "parameters": {"type": "object", "description": "Ignored: outputs are always JSON."},
                    },
                },
            },
        },
    }


def example_request(model: str, sig: Signature) -> dict[str, Any]:
    """A valid request of batch 1: a half circle in the plane for the encoder, the origin for the decoder."""
    inputs = []
    for t in sig.inputs:
        shape = [1 if d == -1 else d for d in t.shape]
        if model == "encoder" and len(shape) == 3 and shape[2] == 2:
            a = np.linspace(0.0, math.pi, shape[1])
            data = np.stack([64 + 40 * np.cos(a), 64 + 40 * np.sin(a)], axis=1).round(2).ravel().tolist()
        else:
            data = [0.0] * math.prod(shape)
        inputs.append({"name": t.name, "shape": shape, "datatype": t.datatype, "data": data})
    return {"id": "1", "inputs": inputs}


def describe(schema: dict[str, Any], sigs: dict[str, Signature], max_batch: int) -> dict[str, Any]:
    """State each model's tensors in the OpenAPI document: its infer request's schema and examples."""
    paths = schema.get("paths", {})
    for model, sig in sigs.items():
        op = paths.get(f"/v2/models/{model}/infer", {}).get("post")
        if op is None:
            continue
        example = example_request(model, sig)
        first = sig.outputs[0].name
        op["requestBody"] = {
            "required": True,
            "content": {
                "application/json": {
                    "schema": request_schema(model, sig, max_batch),
                    "examples": {
                        "all outputs": {"summary": "Batch of 1, every output", "value": example},
                        "one output": {
                            "summary": f"Only {first}",
                            "value": {**example, "outputs": [{"name": first}]},
                        },
                    },
                }
            },
        }
    return schema
