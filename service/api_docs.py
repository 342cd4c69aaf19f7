"""What the OpenAPI page shows beyond the schemas: error examples per status, curl samples, request examples."""

from __future__ import annotations

from typing import Any

from curve_vae.service import schemas as s

ERROR_EXAMPLES = {
    413: (
        "Request body over CURVE_VAE_MAX_BODY_BYTES.",
        "body: a body of 9000000 bytes exceeds the limit of 8388608 bytes (CURVE_VAE_MAX_BODY_BYTES)",
        "body",
    ),
    422: (
        "Invalid input; the message names the field, curve and point.",
        "curves[0][3][1]: not a finite number",
        "curves[0][3][1]",
    ),
    503: (
        "The model is not loaded yet (see GET /ready), or the server is busy: more requests than "
        "CURVE_VAE_INFERENCE_CONCURRENCY + CURVE_VAE_MAX_QUEUE are running or queued (then with Retry-After).",
        "the model is not loaded yet; GET /ready answers 200 once it is",
        None,
    ),
    401: (
        "The server needs an API key (CURVE_VAE_API_KEYS) and the request sent none or a wrong one.",
        "this service needs an API key: send Authorization: Bearer <key> or X-API-Key: <key>",
        None,
    ),
    504: (
        "The request took longer than CURVE_VAE_REQUEST_TIMEOUT seconds, queueing included.",
        "the request took longer than 60 s (CURVE_VAE_REQUEST_TIMEOUT); send less",
        None,
    ),
}


def error_docs(*codes: int) -> dict[int | str, dict[str, Any]]:
    out: dict[int | str, dict[str, Any]] = {}
    for code in codes:
        description, detail, loc = ERROR_EXAMPLES[code]
        errors = [{"loc": loc, "msg": detail.split(": ", 1)[1]}] if loc else []
        out[code] = {
            "model": s.ErrorResponse,
            "description": description,
            "content": {"application/json": {"example": {"detail": detail, "errors": errors}}},
        }
    return out


def curl_sample(path: str, body: str | None = None) -> dict[str, Any]:
    source = f"curl -s http://127.0.0.1:8000{path}"
    if body is not None:
        source += f" -H 'Content-Type: application/json' -d '{body}'"
    return {"x-codeSamples": [{"lang": "Shell", "label": "curl", "source": source}]}


def example(summary: str, value: dict[str, Any]) -> dict[str, Any]:
    return {"summary": summary, "value": value}


C1, C2, C3 = s.EXAMPLE_CURVE, s.EXAMPLE_CURVE_2, s.EXAMPLE_CURVE_3
POST_ERRORS = error_docs(401, 413, 422, 503, 504)
