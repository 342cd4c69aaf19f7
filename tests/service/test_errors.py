"""The API's one error body (service.errors): every validation rule gets the bad input it exists for, and a 4xx whose
message names field, curve and point; paths under /v2 answer in the Open Inference Protocol's format instead.

No input may produce a 5xx: the last tests throw malformed and extreme bodies at every endpoint.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from tests.helpers import FIXTURES, bspline_curves

FILES = FIXTURES / "files"

C = [[0, 0], [1, 2], [2.5, 3.2], [4, 3.5], [5.5, 3], [7, 1.5], [8, 0]]  # a valid curve
Z = [0.0] * 32  # a valid latent


def _with(curve_index: int, point_index: int, coord: int, value: object) -> list:
    curves = [list(map(list, C)) for _ in range(3)]
    curves[curve_index][point_index][coord] = value
    return curves


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


def tensor(name: str, a: np.ndarray, datatype: str = "FP32") -> dict:
    return {"name": name, "shape": list(a.shape), "datatype": datatype, "data": a.ravel().tolist()}


def encoder_request(count: int = 2, seed: int = 0) -> dict:
    return {"inputs": [tensor("curves", bspline_curves(count, seed=seed).astype(np.float32))]}


def error(r, status: int = 400) -> str:
    assert r.status_code == status, r.text
    assert set(r.json()) == {"error"}, r.text
    return r.json()["error"]


def test_api_keys_body_limit_and_unknown_paths_answer_in_the_protocols_format(make_client):
    client = make_client(api_keys="s3cret", max_body_bytes=4096)
    assert "needs an API key" in error(client.post("/v2/models/encoder/infer", json=encoder_request(1)), 401)
    assert "needs an API key" in error(client.get("/v2/models/encoder"), 401)
    assert client.get("/v2/health/live").status_code == 200  # probes need no key
    assert client.get("/v2/health/ready").status_code == 200
    key = {"X-API-Key": "s3cret"}
    assert client.get("/v2/models/encoder", headers=key).status_code == 200
    big = client.post("/v2/models/encoder/infer", json=encoder_request(2), headers=key)  # ~12 kB
    assert "exceeds the limit of 4096 bytes" in error(big, 413)
    decoded = client.post(
        "/v2/models/decoder/infer", json={"inputs": [tensor("latent", np.zeros((1, 32)))]}, headers=key
    )
    assert decoded.status_code == 200
    assert error(client.get("/v2/models/encoder/versions/1", headers=key), 404) == "Not Found"
    assert client.get("/ready").json() == {"status": "ready"}  # the v1 routes keep their own format
    assert set(client.post("/decode", json={}, headers=key).json()) == {"detail", "errors"}


def test_at_most_twenty_problems_are_listed_the_first_one_first(client):
    curve = [[i, "x"] for i in range(30)]  # 30 bad numbers
    r = client.post("/reconstruct", json={"curves": [curve]})
    assert r.status_code == 422
    errors = r.json()["errors"]
    assert [e["loc"] for e in errors] == [f"curves[0][{i}][1]" for i in range(20)]
    assert r.json()["detail"] == "curves[0][0][1]: not a number"


@pytest.mark.parametrize(
    ("path", "protocol"),
    [
        pytest.param("/v2/nothing", True, id="under-v2"),
        pytest.param("/v2", True, id="v2-itself-wrong-method"),
        pytest.param("/v2x", False, id="v2x-is-not-v2"),
        pytest.param("/v1/nothing", False, id="elsewhere"),
    ],
)
def test_only_paths_under_v2_answer_in_the_protocols_format(client, path, protocol):
    r = client.delete(path)
    assert r.status_code in (404, 405)
    assert set(r.json()) == ({"error"} if protocol else {"detail", "errors"}), r.json()
