"""The API's one error format and the handlers that produce it: a line naming the first problem, and the list.

Paths under /v2 (the Open Inference Protocol, service/routes/oip.py) answer in that protocol's format instead,
`{"error": "..."}`, whichever layer refuses the request (API key, body limit, busy, timeout), because its clients
(tritonclient, KServe's) read nothing else."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

from fastapi import Request
from fastapi.exceptions import RequestValidationError
from fastapi.responses import JSONResponse, Response
from starlette.exceptions import HTTPException

from curve_vae.inference.errors import InputError, format_loc
from curve_vae.service.responses import ErrorItem, ErrorResponse

MAX_ERRORS_SHOWN = 20


def error_response(
    status: int,
    errors: Sequence[tuple[str, str]],
    *,
    detail: str | None = None,
    headers: Mapping[str, str] | None = None,
    path: str = "",
) -> JSONResponse:
    """The one error body of the API: a line naming the first problem, and the list of all of them. Under /v2 (the
    Open Inference Protocol, `path`) the protocol's `{"error": line}` instead, which its clients read."""
    if detail is None:
        loc, msg = errors[0]
        detail = f"{loc}: {msg}" if loc else msg
    if speaks_oip(path):
        return oip_error(status, detail, headers=headers)
    items = [ErrorItem(loc=loc, msg=msg) for loc, msg in errors[:MAX_ERRORS_SHOWN]]
    body = ErrorResponse(detail=detail, errors=items)
    return JSONResponse(body.model_dump(), status_code=status, headers=headers)


def speaks_oip(path: str) -> bool:
    """Whether `path` is one of the Open Inference Protocol's (service/routes/oip.py), answered in its error format."""
    return path == "/v2" or path.startswith("/v2/")


def oip_error(status: int, msg: str, *, headers: Mapping[str, str] | None = None) -> JSONResponse:
    """The Open Inference Protocol's error body: `{"error": "..."}`."""
    return JSONResponse({"error": msg}, status_code=status, headers=headers)


def _validation_message(err: dict[str, Any], request: Request) -> tuple[str, str]:
    loc = list(err["loc"])
    if loc[:1] == ["body"]:
        loc = loc[1:]
    kind, ctx = err["type"], err.get("ctx") or {}
    if kind == "json_invalid":
        return "body", f"invalid JSON ({ctx.get('error', 'cannot parse')}) at position {loc[0] if loc else 0}"
    if kind in ("model_attributes_type", "dict_type", "model_type") and not loc:
        hint = ""
        if "json" not in request.headers.get("content-type", ""):
            hint = "; send it with the header Content-Type: application/json"
        return "body", "expected a JSON object" + hint
    messages = {
        "finite_number": "not a finite number",
        "float_parsing": "not a number",
        "float_type": "not a number",
        "int_parsing": "not an integer",
        "int_type": "not an integer",
        "int_from_float": "not an integer",
        "missing": "field required",
        "extra_forbidden": "unknown field",
    }
    msg = messages.get(kind, err["msg"])
    if kind == "float_type" and isinstance(err.get("input"), int) and not isinstance(err.get("input"), bool):
        msg = "not a finite number: too large for a float"
    if kind == "too_short" and len(loc) == 2 and loc[0] == "curves" and isinstance(loc[1], int):
        msg = f"a curve needs at least 4 points, got {ctx.get('actual_length')}"
    elif kind in ("too_short", "too_long") and len(loc) == 3 and loc[0] == "curves":
        msg = f"a point is [x, y]: exactly 2 numbers, got {ctx.get('actual_length')}"
    elif kind == "list_type" and len(loc) == 2 and loc[0] == "curves" and isinstance(err.get("input"), dict):
        msg = CURVE_OBJECT
    elif kind == "tuple_type" or (kind == "list_type" and len(loc) == 3 and loc[0] == "curves"):
        msg = "a point is [x, y]: exactly 2 numbers"
    return format_loc(loc), msg


def _is_number(x: Any) -> bool:
    return isinstance(x, (int, float)) and not isinstance(x, bool)


def _one_unwrapped_curve(body: Any) -> bool:
    """Whether `curves` holds the points of a single curve ([[x, y], …]) instead of a list of curves."""
    curves = body.get("curves") if isinstance(body, dict) else None
    return (
        isinstance(curves, list)
        and len(curves) > 0
        and all(isinstance(p, list) and len(p) == 2 and all(_is_number(v) for v in p) for p in curves)
    )


CURVE_OBJECT = (
    'a curve is a list of [x, y] points, not an object: send each curve\'s "points", {"curves": [[[x, y], ...], ...]} '
    "(the page's JSON export as it is: curve-vae reconstruct FILE reads it)"
)
UNWRAPPED = 'expected a list of curves, got one curve\'s points: wrap it in a list, {"curves": [[[x, y], [x, y], ...]]}'


async def on_validation_error(request: Request, exc: Exception) -> Response:
    assert isinstance(exc, RequestValidationError)
    errors = exc.errors()
    if speaks_oip(request.url.path):  # the protocol answers a request it cannot read with 400
        loc, msg = _validation_message(errors[0], request)
        return oip_error(400, f"{loc}: {msg}")
    if _one_unwrapped_curve(getattr(exc, "body", None)) and any(
        list(e["loc"])[1:2] == ["curves"] and len(e["loc"]) == 4 for e in errors
    ):
        return error_response(422, [("curves", UNWRAPPED)])
    return error_response(422, [_validation_message(e, request) for e in errors])


async def on_input_error(request: Request, exc: Exception) -> Response:
    assert isinstance(exc, InputError)
    return error_response(422, [(format_loc(exc.loc), exc.msg)])


async def on_http_error(request: Request, exc: Exception) -> Response:
    assert isinstance(exc, HTTPException)
    if exc.status_code == 400 and exc.detail == "There was an error parsing the body":
        # FastAPI's answer to bodies json.loads rejects with something other than a syntax error
        # (an integer of over 4300 digits): the same 422 as any other unreadable JSON.
        return error_response(422, [("body", "invalid JSON (cannot parse the body)")])
    return error_response(exc.status_code, [], detail=str(exc.detail), headers=exc.headers, path=request.url.path)
