"""curve_vae.client.calls: the request each call sends (a batch of curves of one length and enough points as a .npy
body with the other fields in the query, else JSON) and each answer parsed into its result, arrays by name."""

from __future__ import annotations

import io

import numpy as np
import orjson
import pytest

from curve_vae.client import calls
from curve_vae.client.results import Augmented, Curves, ModelRef, Reconstructed, Sampled

MODEL = ModelRef("m", "1", "0.15.0", {"encoder.onnx": "e" * 64})
CURVE = [[0.0, 0.0], [1.0, 2.0], [2.0, 1.0], [3.0, 3.0]]


def test_a_small_batch_goes_as_json_with_its_fields():
    fields = {"pose": "as_is", "n_points": 9}
    call = calls.curves_call("/reconstruct", [CURVE, CURVE], fields, calls.parse_reconstructed, npy_points=9)
    assert (call.method, call.path, call.content_type, call.params) == ("POST", "/reconstruct", "application/json", {})
    assert orjson.loads(call.body()) == {"curves": [CURVE, CURVE], "pose": "as_is", "n_points": 9}


def test_a_large_batch_of_one_length_goes_as_npy_with_the_fields_in_the_query():
    curves = np.random.default_rng(0).normal(size=(3, 4, 2))
    fields = {"pose": "as_is", "n_points": 9, "metrics": True, "refine": 0}
    call = calls.curves_call("/encode", list(curves), fields, calls.parse_encoded, npy_points=12)
    assert call.content_type == "application/x-npy" and call.json is None
    sent = np.load(io.BytesIO(call.body()), allow_pickle=False)
    assert sent.dtype == np.float64 and np.array_equal(sent, curves)
    assert call.params == {"pose": "as_is", "n_points": "9", "metrics": "true", "refine": "0"}


@pytest.mark.parametrize(
    "curves",
    [pytest.param([CURVE * 4, CURVE * 3], id="lengths-differ"), pytest.param([CURVE], id="too-few-points")],
)
def test_other_batches_go_as_json(curves):
    call = calls.curves_call("/encode", curves, {}, calls.parse_encoded, npy_points=12)
    assert call.content_type == "application/json" and orjson.loads(call.body()) == {"curves": curves}


def test_a_call_without_a_body_sends_none():
    assert calls.Call("GET", "/model", calls.parse_json).body() is None


def test_the_reading_and_output_fields_are_those_set():
    assert calls.reading(None, "search", None, 0) == {"pose": "search", "refine": 0}
    assert calls.output(None, "both", False) == {"output": "both", "metrics": False}


def test_a_reconstruction_answer_is_its_arrays_and_the_model():
    body = orjson.dumps({"curves": [CURVE, CURVE[:3]], "mse": [0.5, 0.25], "splines": None})
    got = calls.parse_reconstructed(body, MODEL)
    assert isinstance(got, Reconstructed) and got.model == MODEL
    assert [c.tolist() for c in got.curves] == [CURVE, CURVE[:3]]  # lengths differ: a list
    assert got.mse.tolist() == [0.5, 0.25] and got.splines is None and got.metrics is None


def test_a_sample_answer_types_its_fields():
    body = orjson.dumps(
        {"curves": [CURVE], "latents": [[0.1, 0.2]], "seed": 7, "prior": "learned", "rejected": 2, "invalid": 0}
    )
    got = calls.parse_sampled(body, MODEL)
    assert isinstance(got, Sampled) and got.curves.shape == (1, 4, 2)
    assert (got.seed, got.prior, got.rejected, got.invalid) == (7, "learned", 2, 0)
    assert got.latents.tolist() == [[0.1, 0.2]]


def test_an_augment_page_and_an_npy_chunk():
    page = {"curves": [CURVE], "sources": [[2, 0]], "weights": [[0.75, 0.25]], "seed": 3, "offset": 40}
    got = calls.parse_augmented(orjson.dumps(page), MODEL)
    assert isinstance(got, Augmented) and (got.seed, got.offset) == (3, 40)
    assert got.sources.dtype == np.int64 and got.sources.tolist() == [[2, 0]] and got.weights.tolist() == [[0.75, 0.25]]
    buf = io.BytesIO()
    np.save(buf, np.ones((2, 4, 2), np.float32))
    assert calls.parse_npy(buf.getvalue(), MODEL).shape == (2, 4, 2)


def test_a_decode_call_sends_latents_and_parses_curves():
    call = calls.decode_call(np.zeros((1, 3)), {"n_points": 5})
    assert call.path == "/decode" and orjson.loads(call.body()) == {"latents": [[0.0, 0.0, 0.0]], "n_points": 5}
    got = call.parse(orjson.dumps({"curves": [CURVE]}), MODEL)
    assert type(got) is Curves and got.curves.shape == (1, 4, 2)
