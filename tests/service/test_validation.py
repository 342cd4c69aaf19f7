"""Every validation rule gets the bad input it exists for: a 4xx whose message names field, curve and point.

No input may produce a 5xx: the last tests throw malformed and extreme bodies at every endpoint.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from tests.helpers import FIXTURES

FILES = FIXTURES / "files"

C = [[0, 0], [1, 2], [2.5, 3.2], [4, 3.5], [5.5, 3], [7, 1.5], [8, 0]]  # a valid curve
Z = [0.0] * 32  # a valid latent
LIMITS = {"max_curves": 4, "max_points": 300, "max_body_bytes": 20_000}


def _with(curve_index: int, point_index: int, coord: int, value: object) -> list:
    curves = [list(map(list, C)) for _ in range(3)]
    curves[curve_index][point_index][coord] = value
    return curves


@pytest.fixture
def limited(make_client):
    return make_client(**LIMITS)


# (path, JSON body or raw text, expected status, expected start of "detail")
CASES = [
    # --- numbers
    pytest.param(
        "/encode", '{"curves": [[[0,0],[1,2],[2,3],[3,NaN]]]}', 422, "curves[0][3][1]: not a finite number", id="nan"
    ),
    pytest.param(
        "/encode",
        '{"curves": [[[0,0],[1,2],[Infinity,3],[3,1]]]}',
        422,
        "curves[0][2][0]: not a finite number",
        id="infinity",
    ),
    pytest.param(
        "/encode",
        '{"curves": [[[0,0],[1,2],[2,3],[3,1]], [[0,0],[1,-1e999],[2,3],[3,1]]]}',
        422,
        "curves[1][1][1]: not a finite number",
        id="overflowing-literal",
    ),
    pytest.param("/encode", {"curves": _with(2, 5, 0, "x")}, 422, "curves[2][5][0]: not a number", id="string"),
    pytest.param("/encode", {"curves": _with(1, 6, 1, None)}, 422, "curves[1][6][1]: not a number", id="null"),
    pytest.param("/encode", {"curves": _with(0, 0, 0, True)}, 422, "curves[0][0][0]: not a number", id="boolean"),
    # --- points and curves
    pytest.param(
        "/encode",
        {"curves": [[[0, 0], [1, 2, 3], [2, 3], [3, 1]]]},
        422,
        "curves[0][1]: a point is [x, y]: exactly 2 numbers, got 3",
        id="three-coordinates",
    ),
    pytest.param(
        "/encode",
        {"curves": [[[0, 0], [1], [2, 3], [3, 1]]]},
        422,
        "curves[0][1][1]: field required",
        id="one-coordinate",
    ),
    pytest.param(
        "/encode",
        {"curves": [[[0, 0], 5, [2, 3], [3, 1]]]},
        422,
        "curves[0][1]: a point is [x, y]",
        id="point-not-a-pair",
    ),
    pytest.param(
        "/encode",
        {"curves": [C, [[0, 0], [1, 1], [2, 0]]]},
        422,
        "curves[1]: a curve needs at least 4 points, got 3",
        id="three-points",
    ),
    pytest.param(
        "/reconstruct",
        {"curves": [C, C, [[2, 2]] * 9]},
        422,
        "curves[2]: all 9 points coincide",
        id="coincident-points",
    ),
    pytest.param("/encode", {"curves": []}, 422, "curves: List should have at least 1 item", id="no-curves"),
    pytest.param(
        "/encode",
        {"curves": C},
        422,
        "curves: expected a list of curves, got one curve's points",
        id="curve-not-nested",
    ),
    pytest.param(
        "/encode", {"curves": _with(0, 2, 1, "1.5")}, 422, "curves[0][2][1]: not a number", id="numeric-string"
    ),
    pytest.param("/encode", {}, 422, "curves: field required", id="missing-curves"),
    # --- fields
    pytest.param(
        "/encode", {"curves": [C], "frame": "pixels"}, 422, "frame: Input should be 'auto' or 'model'", id="bad-frame"
    ),
    pytest.param("/reconstruct", {"curves": [C], "npoints": 50}, 422, "npoints: unknown field", id="misspelt-field"),
    pytest.param(
        "/reconstruct",
        {"curves": [C], "n_points": 3},
        422,
        "n_points: Input should be greater than or equal to 4",
        id="n-points-too-small",
    ),
    pytest.param(
        "/reconstruct", {"curves": [C], "n_points": 2.5}, 422, "n_points: not an integer", id="n-points-fraction"
    ),
    pytest.param(
        "/reconstruct", {"curves": [C], "n_points": "50"}, 422, "n_points: not an integer", id="n-points-string"
    ),
    # --- latents
    pytest.param(
        "/decode",
        {"latents": [Z, [0.0] * 31]},
        422,
        "latents[1]: expected 32 numbers (the model's latent_dim), got 31",
        id="latent-too-short",
    ),
    pytest.param("/decode", {"latents": [Z + [0.0]]}, 422, "latents[0]: expected 32 numbers", id="latent-too-long"),
    pytest.param("/decode", {"latents": []}, 422, "latents: List should have at least 1 item", id="no-latents"),
    pytest.param(
        "/decode",
        '{"latents": [[' + ",".join(["0"] * 31) + ",NaN]]}",
        422,
        "latents[0][31]: not a finite number",
        id="latent-nan",
    ),
    pytest.param(
        "/decode",
        {"latents": [[1e300] * 32]},
        422,
        "latents[0]: values beyond float32 range",
        id="latent-beyond-float32",
    ),
    pytest.param(
        "/decode",
        {"latents": [Z, Z], "frames": [{"center": [0, 0], "size": 1}]},
        422,
        "frames: expected one frame per latent (2), got 1",
        id="frames-count",
    ),
    pytest.param(
        "/decode",
        {"latents": [Z], "frames": [{"center": [0, 0], "size": 0}]},
        422,
        "frames[0].size: Input should be greater than 0",
        id="frame-size-zero",
    ),
    # --- interpolation
    pytest.param("/interpolate", {"curves": [C]}, 422, "curves: List should have at least 2 items", id="one-curve"),
    pytest.param(
        "/interpolate",
        {"curves": [C, C], "steps": 1},
        422,
        "steps: Input should be greater than or equal to 2",
        id="one-step",
    ),
    pytest.param(
        "/interpolate",
        {"curves": [C, C], "steps": 3, "weights": [[1, 0]]},
        422,
        "body: give either steps or weights, not both",
        id="steps-and-weights",
    ),
    pytest.param(
        "/interpolate",
        {"curves": [C, C, C], "weights": [[0.5, 0.5, 0], [0.5, 0.5]]},
        422,
        "weights[1]: expected 3 numbers, one per input curve, got 2",
        id="weights-row-length",
    ),
    pytest.param(
        "/interpolate",
        {"curves": [C, C], "weights": [[0.5, 0.5], [0.6, 0.6]]},
        422,
        "weights[1]: weights must sum to 1, got 1.2",
        id="weights-sum",
    ),
    pytest.param(
        "/interpolate",
        '{"curves": [[[0,0],[1,2],[2,3],[3,1]], [[0,0],[1,2],[2,3],[3,1]]], "weights": [[NaN, 1]]}',
        422,
        "weights[0][0]: not a finite number",
        id="weights-nan",
    ),
    pytest.param(
        "/interpolate",
        {"curves": [C, C], "weights": [[1e30, 1 - 1e30]]},
        422,
        "weights[0]: weights must sum to 1, got 0",
        id="weights-cancelling",
    ),
    pytest.param(
        "/interpolate",
        {"curves": [C, C], "weights": []},
        422,
        "weights: List should have at least 1 item",
        id="no-weights",
    ),
    # --- sample and augment
    pytest.param(
        "/sample", {"count": 0}, 422, "count: Input should be greater than or equal to 1", id="sample-count-zero"
    ),
    pytest.param(
        "/sample",
        {"count": 2, "temperature": -1},
        422,
        "temperature: Input should be greater than or equal to 0",
        id="sample-negative-temperature",
    ),
    pytest.param(
        "/sample",
        {"count": 2, "seed": -3},
        422,
        "seed: Input should be greater than or equal to 0",
        id="sample-negative-seed",
    ),
    pytest.param("/sample", {"count": 2, "seed": 1.5}, 422, "seed: not an integer", id="sample-fractional-seed"),
    pytest.param("/sample", {"count": 300}, 422, "count: at most 256, got 300", id="sample-count-over-limit"),
    pytest.param(
        "/augment",
        {"curves": [C, C], "count": 2, "mode": "triplet"},
        422,
        "curves: mode triplet needs at least 3 curves, got 2",
        id="augment-triplet-of-two",
    ),
    pytest.param(
        "/augment",
        {"curves": [C, C], "count": 2, "mode": "quad"},
        422,
        "mode: Input should be 'pair' or 'triplet'",
        id="augment-bad-mode",
    ),
    pytest.param(
        "/augment",
        {"curves": [C], "count": 2},
        422,
        "curves: List should have at least 2 items",
        id="augment-one-curve",
    ),
    pytest.param(
        "/augment",
        {"curves": [C, C], "count": 1000},
        422,
        "count: at most 256, got 1000",
        id="augment-count-over-limit",
    ),
    pytest.param(
        "/augment",
        {"curves": [C, C], "count": 2, "neighbours": 0},
        422,
        "neighbours: Input should be greater than or equal to 1",
        id="augment-no-neighbours",
    ),
    pytest.param(
        "/augment",
        {"curves": [C, C, C], "count": 2, "neighbours": 3},
        422,
        "neighbours: at most 2 (each curve has 2 others), got 3; omit it to mix any curve with any other",
        id="augment-more-neighbours-than-curves",
    ),
    pytest.param(
        "/augment",
        {"curves": [C, C, C], "count": 2, "mode": "triplet", "neighbours": 1},
        422,
        "neighbours: mode triplet mixes each curve with 2 others: at least 2, got 1",
        id="augment-triplet-of-one-neighbour",
    ),
    pytest.param(
        "/augment",
        {"curves": [C, C], "count": 2, "offset": -1},
        422,
        "offset: Input should be greater than or equal to 0",
        id="augment-negative-offset",
    ),
    pytest.param(
        "/augment",
        {"curves": [C, C], "count": 2, "format": "csv"},
        422,
        "format: Input should be 'json' or 'npy'",
        id="augment-bad-format",
    ),
    pytest.param(
        "/augment",
        {"curves": [C, C], "count": 300000, "format": "npy"},
        422,
        "count: at most 100000, got 300000 (format npy, CURVE_VAE_MAX_STREAM_CURVES)",
        id="augment-stream-over-limit",
    ),
    pytest.param(
        "/sample",
        {"count": 2, "frame": {"center": [0, 0], "size": 0}},
        422,
        "frame.size: Input should be greater than 0",
        id="sample-frame-of-size-zero",
    ),
    pytest.param("/sample", {"count": 2, "metrics": "yes"}, 422, "metrics: Input should be a valid boolean", id="m"),
    pytest.param(
        "/interpolate",
        '{"curves": [[[0,0],[1,2],[2,3],[3,1]], [[0,0],[1,2],[2,3],[3,1]]], "weights": [[1e308, 1e308]]}',
        422,
        "weights[0]: weights must sum to 1, got inf",
        id="weights-overflowing-sum",
    ),
    pytest.param(
        "/encode",
        '{"curves": [[[0,0],[1,%s],[2,3],[3,1]]]}' % ("9" * 400),
        422,
        "curves[0][1][1]: not a finite number",
        id="integer-beyond-float",
    ),
    # --- the body
    pytest.param("/encode", '{"curves": [[[0,0],[1,2]', 422, "body: invalid JSON", id="truncated-json"),
    pytest.param("/encode", "[1, 2, 3]", 422, "body: expected a JSON object", id="array-body"),
    pytest.param("/encode", "", 422, "body: field required", id="empty-body"),
    pytest.param(
        "/encode",
        '{"curves": [[[0,0],[1,%s],[2,3],[3,1]]]}' % ("9" * 5000),
        422,
        "body: invalid JSON",
        id="integer-of-5000-digits",
    ),
]


@pytest.mark.parametrize("path,body,status,detail", CASES)
def test_bad_input_is_rejected_with_a_message_naming_where(client, path, body, status, detail):
    if isinstance(body, str):
        r = client.post(path, content=body, headers={"Content-Type": "application/json"})
    else:
        r = client.post(path, json=body)
    assert r.status_code == status, r.text
    out = r.json()
    assert out["detail"].startswith(detail), out["detail"]
    assert out["errors"] and out["errors"][0]["loc"] == detail.split(":")[0]


LIMIT_CASES = [
    pytest.param("/encode", {"curves": [C] * 5}, "curves: at most 4 curves per request, got 5", id="too-many-curves"),
    pytest.param(
        "/fit", {"curves": [C] * 5, "n_ctrl": 4}, "curves: at most 4 curves per request, got 5", id="fit-curves"
    ),
    pytest.param(
        "/fit",
        {"curves": [C], "n_ctrl": 4, "n_points": 301},
        "n_points: at most 300, got 301",
        id="fit-n-points-over-limit",
    ),
    pytest.param(
        "/revolve",
        {"curve": np.linspace(0, 1, 602).reshape(301, 2).tolist()},
        "curve: at most 300 points, got 301",
        id="revolve-profile-too-long",
    ),
    pytest.param(
        "/reconstruct",
        {"curves": [C, np.linspace(0, 1, 602).reshape(301, 2).tolist()]},
        "curves[1]: at most 300 points per curve, got 301",
        id="too-many-points",
    ),
    pytest.param(
        "/reconstruct", {"curves": [C], "n_points": 301}, "n_points: at most 300, got 301", id="n-points-over-limit"
    ),
    pytest.param(
        "/decode", {"latents": [Z] * 5}, "latents: at most 4 latents per request, got 5", id="too-many-latents"
    ),
    pytest.param(
        "/interpolate",
        {"curves": [C, C], "steps": 5},
        "steps: 5 steps over 2 curves make 5 curves; at most 4",
        id="steps-over-limit",
    ),
    pytest.param(
        "/interpolate",
        {"curves": [C, C, C], "steps": 3},
        "steps: 3 steps over 3 curves make 6 curves",
        id="triplet-grid-over-limit",
    ),
    pytest.param(
        "/interpolate",
        {"curves": [C, C], "weights": [[1, 0]] * 5},
        "weights: at most 4 rows, got 5",
        id="too-many-weight-rows",
    ),
]


@pytest.mark.parametrize("path,body,detail", LIMIT_CASES)
def test_configured_limits(limited, path, body, detail):
    r = limited.post(path, json=body)
    assert r.status_code == 422, r.text
    assert r.json()["detail"].startswith(detail), r.json()["detail"]


def test_body_over_the_limit_is_413(limited):
    big = {"curves": [np.linspace(0, 1, 600).reshape(300, 2).tolist()] * 4}
    r = limited.post("/reconstruct", json=big)
    assert r.status_code == 413
    assert r.json()["detail"].startswith("body: a body of") and "20000 bytes" in r.json()["detail"]


def test_streamed_body_over_the_limit_is_413(limited):
    def chunks():  # no Content-Length: the limit must hold while reading
        yield b'{"curves": ['
        for _ in range(100):
            yield json.dumps(C).encode() * 5 + b","
        yield b"]}"

    r = limited.post("/encode", content=chunks(), headers={"Content-Type": "application/json"})
    assert r.status_code == 413 and "streamed body" in r.json()["detail"]


def test_form_encoded_body_gets_a_hint(client):
    r = client.post(
        "/encode", content=json.dumps({"curves": [C]}), headers={"Content-Type": "application/x-www-form-urlencoded"}
    )
    assert r.status_code == 422 and "Content-Type: application/json" in r.json()["detail"]


@pytest.mark.parametrize(
    "path,body",
    [
        pytest.param("/reconstruct", {"curves": [(np.array(C) * 1e200).tolist()]}, id="huge-coordinates"),
        pytest.param("/reconstruct", {"curves": [(np.array(C) * 1e-320).tolist()]}, id="subnormal-extent"),
        pytest.param("/encode", {"curves": [(np.array(C) * 1e300).tolist()], "frame": "model"}, id="huge-model-frame"),
        pytest.param(
            "/reconstruct", {"curves": [(np.array(C) * 1e30).tolist()], "frame": "model"}, id="far-model-frame"
        ),
        pytest.param("/decode", {"latents": [[3e38] * 32]}, id="latent-near-float32-max"),
        pytest.param("/interpolate", {"curves": [C, C], "weights": [[1e38, 1 - 1e38 + 1]]}, id="extreme-weights"),
        pytest.param(
            "/interpolate",
            {"curves": [C, (np.array(C) * 1e-6).tolist()], "weights": [[-1e6, 1e6 + 1]]},
            id="frame-extrapolation",
        ),
        pytest.param("/decode", {"latents": [Z], "n_points": 10**12}, id="n-points-huge"),
        pytest.param(
            "/decode",
            {"latents": [Z], "frames": [{"center": [1.7e308, -1.7e308], "size": 1.7e308}]},
            id="frame-overflow",
        ),
        pytest.param("/interpolate", {"curves": [C, C], "steps": 10**40}, id="steps-huge"),
        pytest.param("/fit", {"curves": [(np.array(C) * 1e300).tolist()], "n_ctrl": 5}, id="fit-huge"),
        pytest.param("/fit", {"curves": [(np.array(C) * 1e-320).tolist()], "n_ctrl": 5}, id="fit-subnormal"),
        pytest.param("/fit", {"curves": [C], "n_ctrl": 10**30}, id="fit-n-ctrl-huge"),
        pytest.param("/revolve", {"curve": (np.array(C) * 1e300).tolist()}, id="revolve-huge"),
        pytest.param("/revolve", {"curve": (np.array(C) * 1e300).tolist(), "format": "stl"}, id="revolve-huge-stl"),
        pytest.param("/revolve", {"curve": (np.array(C) * 1e38).tolist(), "format": "stl"}, id="revolve-stl-float32"),
        pytest.param("/revolve", {"curve": (np.array(C) * 1e-320).tolist()}, id="revolve-subnormal"),
        pytest.param("/revolve", {"curve": C, "segments": 10**30}, id="revolve-segments-huge"),
        pytest.param("/revolve", {"curve": C, "axis_position": -1.7e308}, id="revolve-axis-far"),
        pytest.param("/sample", {"count": 2, "frame": {"center": [1e308, 1e308], "size": 1e308}}, id="sample-frame"),
        pytest.param(
            "/augment", {"curves": [C, C], "count": 2, "offset": 2**53 - 3, "seed": 2**53 - 1}, id="augment-last-items"
        ),
        pytest.param("/augment", {"curves": [C, C], "count": 2, "neighbours": 10**30}, id="augment-neighbours-huge"),
    ],
)
def test_extreme_inputs_never_give_5xx(client, path, body):
    r = client.post(path, json=body)
    assert r.status_code < 500, r.text
    if r.status_code != 200:
        assert r.json()["errors"][0]["loc"]


@pytest.mark.parametrize(
    "path", ["/encode", "/decode", "/reconstruct", "/interpolate", "/sample", "/augment", "/fit", "/revolve"]
)
def test_garbage_never_gives_5xx(client, path):
    bodies = [
        "null",
        "0",
        '"x"',
        "{}",
        '{"curves": null}',
        '{"curves": [[]]}',
        '{"curves": [[[]]]}',
        '{"latents": [[]]}',
        '{"curves": {"a": 1}}',
        '{"latents": "z"}',
        "\xff\xfe",
        "{" * 1000 + "}" * 1000,
    ]
    for body in bodies:
        r = client.post(
            path, content=body.encode("utf-8", "surrogateescape"), headers={"Content-Type": "application/json"}
        )
        assert 400 <= r.status_code < 500, (body[:50], r.status_code, r.text)
        assert r.json()["detail"]


def test_integral_numbers_are_integers_as_in_json_schema(client):
    """JSON Schema's "integer" admits 3.0; so does the service, and 3.5 stays an error."""
    ok = client.post("/sample", json={"count": 3.0, "seed": 7.0, "n_points": 50.0})
    same = client.post("/sample", json={"count": 3, "seed": 7, "n_points": 50})
    assert ok.status_code == 200 and ok.json() == same.json()
    assert client.post("/sample", json={"count": 3.5}).json()["detail"] == "count: not an integer"


@pytest.mark.parametrize("path", ["/encode", "/reconstruct", "/interpolate", "/augment"])
def test_one_curve_not_wrapped_in_a_list_gets_one_error_that_says_wrap_it(client, path):
    r = client.post(path, json={"curves": [[0, 0], [1, 2], [2, 3], [3, 1]]})
    assert r.status_code == 422
    body = r.json()
    assert len(body["errors"]) == 1 and "wrap it in a list" in body["detail"], body


def test_a_body_without_content_type_gets_the_header_hint(client):
    r = client.post("/encode", content=json.dumps({"curves": [C]}).encode(), headers={"Content-Type": ""})
    assert r.status_code == 422 and "Content-Type: application/json" in r.json()["detail"], r.json()


@pytest.mark.parametrize("path", ["/reconstruct", "/interpolate"])
def test_the_pages_json_export_posted_as_it_is_gets_told_what_to_send(client, path):
    """The page's export holds objects with "points"; the API takes point arrays, and says so (the CLI reads it)."""
    export = json.loads((FILES / "page-export.json").read_text())
    r = client.post(path, json=export)
    assert r.status_code == 422
    detail = r.json()["detail"]
    assert detail.startswith("curves[0]: a curve is a list of [x, y] points, not an object: send each curve's")
    assert "curve-vae reconstruct FILE reads it" in detail
