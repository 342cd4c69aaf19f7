"""What the OpenAPI page shows beyond the schemas: error examples per status, curl samples, request examples."""

from __future__ import annotations

from typing import Any

from curve_vae.service import responses as r

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
        "headers.authorization",
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
        msg = detail.removeprefix(f"{loc}: ")  # a field's message follows its name; a header's is the detail itself
        errors = [{"loc": loc, "msg": msg}] if loc else []
        out[code] = {
            "model": r.ErrorResponse,
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


# A quarter-ellipse-like arc; any frame, any length ≥ 4: the examples work as pasted.
EXAMPLE_CURVE = [[0.0, 0.0], [1.0, 2.0], [2.5, 3.2], [4.0, 3.5], [5.5, 3.0], [7.0, 1.5], [8.0, 0.0]]
EXAMPLE_CURVE_2 = [[0.0, 0.0], [1.5, 0.5], [3.0, 2.0], [4.0, 4.0], [5.0, 6.5], [6.5, 8.0], [8.0, 8.5]]
EXAMPLE_CURVE_3 = [[0.0, 4.0], [2.0, 5.0], [4.0, 4.0], [6.0, 2.0], [8.0, 1.0], [10.0, 2.0], [12.0, 4.0]]
C1, C2, C3 = EXAMPLE_CURVE, EXAMPLE_CURVE_2, EXAMPLE_CURVE_3
POST_ERRORS = error_docs(401, 413, 422, 503, 504)

ONE_CURVE = '{"curves": [[[0,0],[1,2],[2.5,3.2],[4,3.5],[5.5,3],[7,1.5],[8,0]]]}'
TWO_CURVES = (
    '{"curves": [[[0,0],[1,2],[2.5,3.2],[4,3.5],[5.5,3],[7,1.5],[8,0]], '
    "[[0,0],[1.5,0.5],[3,2],[4,4],[5,6.5],[6.5,8],[8,8.5]]]}"
)
THREE_CURVES = TWO_CURVES[:-2] + ", [[0,4],[2,5],[4,4],[6,2],[8,1],[10,2],[12,4]]]}"

ENCODE = {
    "one curve": example("A curve in its own frame", {"curves": [C1]}),
    "model frame": example(
        "Already in the 128×128 plane",
        {"curves": [[[14, 64], [40, 100], [64, 110], [90, 95], [114, 64]]], "frame": "model"},
    ),
}
RECONSTRUCT = {
    "one curve": example("A curve in its own frame, back at its own 7 points", {"curves": [C1]}),
    "resampled": example("Two curves, returned at 100 points each", {"curves": [C1, C2], "n_points": 100}),
    "points and spline": example(
        "The reconstruction as points and as the B-spline they lie on", {"curves": [C1], "output": "both"}
    ),
    "the search": example(
        "Six poses and every natural reading tried, the closest kept",
        {"curves": [C1], "pose": "search", "spacing": "search"},
    ),
}
INTERPOLATE = {
    "pair": example("Pair, 5 curves from the first to the second (paper eq. 9)", {"curves": [C1, C2], "steps": 5}),
    "triplet": example("Triplet, barycentric grid of 6 curves (paper eq. 10)", {"curves": [C1, C2, C3], "steps": 3}),
    "weights": example("Explicit weights, one entry per curve", {"curves": [C1, C2], "weights": [[0.25, 0.75]]}),
    "as B-splines": example(
        "The middle curve as a B-spline: control points, knots, degree and the parameter of each point",
        {"curves": [C1, C2], "weights": [[0.5, 0.5]], "output": "bspline"},
    ),
}
DECODE = {
    "origin": example("The centre of the latent space, 50 points", {"latents": [[0.0] * 32], "n_points": 50}),
    "in a frame": example(
        "Mapped into a frame from /encode",
        {"latents": [[0.0] * 32], "frames": [{"center": [4.0, 1.75], "size": 8.0}]},
    ),
}
EXPLORE = {
    "3×3 grid": example("The 3×3 grid around a curve, ±1 standard deviation", {"curves": [C1]}),
    "a wider row": example(
        "Five curves along the direction the data varies most, ±2 standard deviations",
        {"curves": [C1], "steps": 5, "directions": 1, "spread": 2.0},
    ),
}
SAMPLE = {
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
AUGMENT = {
    "pairs": example("Four random pair interpolants", {"curves": [C1, C2, C3], "count": 4, "seed": 1}),
    "triplets": example("Two random triplet interpolants", {"curves": [C1, C2, C3], "count": 2, "mode": "triplet"}),
    "neighbours, second page": example(
        "Pairs of near neighbours only; curves 4 and 5 of the seeded sequence",
        {"curves": [C1, C2, C3], "count": 2, "neighbours": 1, "seed": 1, "offset": 4},
    ),
    "npy": example(
        "1000 curves as a binary .npy file (curl -o batch.npy)",
        {"curves": [C1, C2, C3], "count": 1000, "seed": 1, "n_points": 64, "format": "npy"},
    ),
}
