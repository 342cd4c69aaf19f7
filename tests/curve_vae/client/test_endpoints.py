"""curve_vae.client.endpoints: each endpoint method builds the request the service expects — the reading's fields
(only those the caller set), the output's, the curves as JSON or as a .npy body, one curve as a batch of one — and
both clients share them.
Checked on the calls themselves, with a recording stand-in for the transport; the requests are then accepted by
the real app's schemas (TestClient), so the names and values are the service's."""

from __future__ import annotations

import io

import numpy as np
import orjson
import pytest

from curve_vae.client import calls as k
from curve_vae.client.endpoints import NPY_POINTS, Endpoints
from curve_vae.errors import InvalidInput

CURVE = np.array([[0.0, 0.0], [1.0, 2.0], [2.0, 1.5], [3.0, 0.0]])


class Recorder(Endpoints):
    """Endpoints whose transport records each call instead of sending it."""

    def __init__(self, npy_points: int = NPY_POINTS) -> None:
        self.calls: list[k.Call] = []
        self.npy_points = npy_points

    def _call(self, call: k.Call) -> k.Call:
        self.calls.append(call)
        return call


def _json(call: k.Call) -> dict:
    return orjson.loads(call.body())


def test_only_the_reading_fields_set_are_sent():
    rec = Recorder()
    assert "pose" not in _json(rec.encode([CURVE]))  # the server's default: the model's own reading
    body = _json(rec.reconstruct([CURVE], pose="learned", spacing="search", refine=2, n_points=20))
    assert {k_: body[k_] for k_ in ("pose", "spacing", "refine", "n_points")} == {
        "pose": "learned",
        "spacing": "search",
        "refine": 2,
        "n_points": 20,
    }
    assert "frame" not in body and "output" not in body


def test_augment_takes_the_whole_reading_refine_included():
    rec = Recorder()
    call = rec.augment([CURVE, CURVE * 2], 3, seed=1, pose="canonical", refine=1, frame="auto")
    body = _json(call)
    assert (body["count"], body["seed"], body["pose"], body["refine"], body["frame"]) == (3, 1, "canonical", 1, "auto")
    assert call.path == "/augment" and call.content_type == "application/json"


def test_many_points_of_one_length_go_as_a_npy_body_with_the_fields_in_the_query():
    rec = Recorder(npy_points=8)
    call = rec.reconstruct([CURVE, CURVE + 1], pose="as_is", n_points=50)
    assert call.content_type == "application/x-npy" and call.json is None
    np.testing.assert_array_equal(np.load(io.BytesIO(call.content)), np.stack([CURVE, CURVE + 1]))
    assert call.params == {"pose": "as_is", "n_points": "50"}  # a string as itself, anything else as JSON
    few = rec.reconstruct([CURVE])  # 4 points < 8: JSON
    assert few.content_type == "application/json" and len(_json(few)["curves"]) == 1


def test_one_curve_is_sent_as_a_batch_of_one_by_every_method_that_takes_curves():
    rec = Recorder(npy_points=4)
    one = [rec.encode(CURVE), rec.reconstruct(CURVE), rec.fit(CURVE, n_ctrl=4), rec.reconstruct(CURVE.tolist())]
    for call in one:
        sent = np.load(io.BytesIO(call.content)) if call.json is None else np.asarray(_json(call)["curves"])
        assert sent.shape == (1, *CURVE.shape), call.path
        np.testing.assert_array_equal(sent[0], CURVE)
    assert one[1].content_type == "application/x-npy"  # 4 points: one curve goes as .npy like any batch


def test_one_curve_to_a_method_that_mixes_curves_is_refused_before_sending():
    rec = Recorder()
    for method, call in [
        ("interpolate", lambda: rec.interpolate(CURVE, steps=3)),
        ("augment", lambda: rec.augment(CURVE.tolist(), 4, seed=1)),
    ]:
        with pytest.raises(InvalidInput, match=f"{method} needs at least 2 curves, got one curve"):
            call()
    assert rec.calls == []


def test_interpolate_sends_steps_or_weights_as_given():
    """CURVE[::-1] is a reversed view, not C-ordered: the body is written all the same (it once raised in orjson)."""
    rec = Recorder()
    assert _json(rec.interpolate([CURVE, CURVE[::-1]], steps=4))["steps"] == 4
    body = _json(rec.interpolate([CURVE, CURVE[::-1]], weights=[[0.25, 0.75]]))
    assert body["weights"] == [[0.25, 0.75]] and "steps" not in body


def test_the_requests_are_the_services_own(client):
    """Every request the endpoints build is accepted by the app (the fixture model), field names and values alike."""
    rec = Recorder()
    calls = [
        rec.encode([CURVE], pose="canonical", spacing="parameter"),
        rec.reconstruct([CURVE], frame="auto", pose="as_is", spacing="arc_length", n_points=30, metrics=True),
        rec.interpolate([CURVE, CURVE * 2], steps=3, pose="canonical"),
        rec.decode(np.zeros((1, 32)), n_points=20, spacing="parameter"),
        rec.sample(2, seed=3, temperature=0.5),
        rec.augment([CURVE, CURVE * 2], 2, seed=1, mode="pair", pose="canonical", refine=0),
        rec.encode(CURVE),  # one curve
        rec.reconstruct(CURVE.tolist(), n_points=10),
        rec.fit(CURVE, n_ctrl=4),
        rec.revolve(CURVE, segments=8, format="stl"),
    ]
    for call in calls:
        r = client.request(call.method, call.path, content=call.body(), headers={"Content-Type": call.content_type})
        assert r.status_code == 200, (call.path, r.text)
