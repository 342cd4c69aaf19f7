"""The v1 request fields (service.fields), through real requests: numbers, points, curves, seeds, frames, the integral
numbers JSON Schema allows, and the reading's choices: each accepted as the OpenAPI page documents it, the rest refused
with a 422 naming the field."""

from __future__ import annotations

import numpy as np
import pytest


def test_integral_numbers_are_integers_as_in_json_schema(client):
    """JSON Schema's "integer" admits 3.0; so does the service, and 3.5 stays an error."""
    ok = client.post("/sample", json={"count": 3.0, "seed": 7.0, "n_points": 50.0})
    same = client.post("/sample", json={"count": 3, "seed": 7, "n_points": 50})
    assert ok.status_code == 200 and ok.json() == same.json()
    assert client.post("/sample", json={"count": 3.5}).json()["detail"] == "count: not an integer"


Z = np.random.default_rng(3).normal(size=(2, 32)).round(6).tolist()


def test_unknown_output_is_a_422(client):
    r = client.post("/decode", json={"latents": Z, "output": "nurbs"})
    assert r.status_code == 422 and "output" in r.json()["detail"]


C = [[0, 0], [1, 2], [2.5, 3.2], [4, 3.5], [5.5, 3], [7, 1.5], [8, 0]]
MAX_SAFE = 2**53 - 1  # the largest integer every JSON parser holds exactly


@pytest.mark.parametrize(
    ("body", "status", "detail"),
    [
        pytest.param({"count": 1, "seed": 0}, 200, None, id="seed-zero"),
        pytest.param({"count": 1, "seed": MAX_SAFE}, 200, None, id="seed-2^53-1"),
        pytest.param({"count": 1, "seed": MAX_SAFE + 1}, 422, "seed: ", id="seed-2^53"),
        pytest.param({"count": 1, "seed": -1}, 422, "seed: ", id="seed-negative"),
        pytest.param({"count": 1, "seed": True}, 422, "seed: ", id="seed-boolean"),
        pytest.param({"count": 1, "n_points": 4}, 200, None, id="n-points-4"),
        pytest.param({"count": 1, "n_points": 3}, 422, "n_points: ", id="n-points-3"),
        pytest.param({"count": 1, "n_points": "50"}, 422, "n_points: not an integer", id="n-points-string"),
        pytest.param({"count": 1, "metrics": "true"}, 422, "metrics: ", id="metrics-string"),
        pytest.param({"count": 1, "frame": {"center": [0, 0], "size": 1e-300}}, 200, None, id="frame-tiny"),
        pytest.param({"count": 1, "frame": {"center": [0, 0], "size": -1}}, 422, "frame.size: ", id="frame-negative"),
        pytest.param({"count": 1, "frame": {"center": [0], "size": 1}}, 422, "frame.center", id="frame-centre-1d"),
        pytest.param({"count": 1, "frame": {"size": 1}}, 422, "frame.center: field required", id="frame-no-centre"),
        pytest.param(
            {"count": 1, "frame": {"center": [0, 0], "size": 1, "mirror": 1}}, 422, "frame.mirror: ", id="mirror-1"
        ),
        pytest.param(
            {"count": 1, "frame": {"center": ["0", 0], "size": 1}},
            422,
            "frame.center[0]: not a number",
            id="centre-str",
        ),
    ],
)
def test_sample_fields_accept_their_range_and_name_what_is_outside_it(client, body, status, detail):
    r = client.post("/sample", json={"valid": False, **body})
    assert r.status_code == status, r.text
    if detail is not None:
        assert r.json()["detail"].startswith(detail), r.json()["detail"]


def test_a_frame_is_applied_as_documented_rotation_mirror_and_reverse(client, runtime):
    """FrameInfo's fields as the OpenAPI page describes them: the model-plane curve is mirrored (x -> -x), turned by
    `rotation` counter-clockwise, reversed, and mapped to `size` about `center`."""
    z = np.random.default_rng(5).normal(size=(1, 32)).tolist()
    plain = np.array(
        client.post("/decode", json={"latents": z, "frames": [{"center": [0, 0], "size": 1}]}).json()["curves"][0]
    )
    frame = {"center": [3, -2], "size": 2, "rotation": np.pi / 2, "mirror": True, "reverse": True}
    moved = np.array(client.post("/decode", json={"latents": z, "frames": [frame]}).json()["curves"][0])
    # Mapping into a frame undoes the pose: the inverse of (mirror, then turn by rotation) is (turn back, then mirror).
    x, y = plain[:, 0], plain[:, 1]
    back = np.stack([y, -x], axis=1)  # turned by -90°
    expected = (back * [-1, 1])[::-1] * 2 + [3, -2]
    np.testing.assert_allclose(moved, expected, atol=1e-9)


OPTIONS = ["frame", "pose", "spacing", "output"]


@pytest.mark.parametrize("field", OPTIONS)
def test_each_documented_choice_is_described_accepted_and_nothing_else(client, field):
    """The OpenAPI page lists each reading option's values and describes each one ("value" quoted in the field's
    description); /reconstruct accepts every listed value (pose "learned" only with a ranker, which the test model
    lacks: a 422 that says so) and refuses one not listed, naming the field."""
    prop = client.get("/openapi.json").json()["components"]["schemas"]["ReconstructRequest"]["properties"][field]
    values = prop["enum"]
    assert len(values) >= 2 and prop["default"] in values
    for value in values:
        assert f'"{value}"' in prop["description"], (field, value)
        r = client.post("/reconstruct", json={"curves": [C], field: value})
        if (field, value) == ("pose", "learned"):
            assert r.status_code == 422 and "ranker" in r.json()["detail"], r.text
        else:
            assert r.status_code == 200, (field, value, r.text)
    r = client.post("/reconstruct", json={"curves": [C], field: "sideways"})
    assert r.status_code == 422 and r.json()["errors"][0]["loc"] == field
