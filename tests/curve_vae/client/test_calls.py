"""curve_vae.client.calls: the request each call sends (a batch of curves of one length and enough points as a .npy
body with the other fields in the query, else JSON) and each answer parsed into its result, arrays by name: the
fields a newer server sends (closeness, repaired, valid, ends, redrawn) typed where present and None where absent,
/fit's fits and /revolve's file typed."""

from __future__ import annotations

import io

import httpx
import numpy as np
import orjson
import pytest

from curve_vae.client import calls
from curve_vae.client.design import BSplineFit, Fitted, Revolved
from curve_vae.client.results import (
    Augmented,
    Closeness,
    Curves,
    Encoded,
    Interpolated,
    ModelRef,
    Reconstructed,
    Sampled,
)

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
    assert calls.reading(None, "search", None, None, 0) == {"pose": "search", "refine": 0}
    assert calls.reading(None, None, None, 2, None) == {"looks": 2}
    assert calls.output(None, "both", False) == {"output": "both", "metrics": False}


def test_a_reconstruction_answer_is_its_arrays_and_the_model():
    body = orjson.dumps({"curves": [CURVE, CURVE[:3]], "mse": [0.5, 0.25], "splines": None})
    got = calls.parse_reconstructed(body, MODEL)
    assert isinstance(got, Reconstructed) and got.model == MODEL
    assert [c.tolist() for c in got.curves] == [CURVE, CURVE[:3]]  # lengths differ: a list
    assert got.mse.tolist() == [0.5, 0.25] and got.splines is None and got.metrics is None
    assert got.closeness is None and got.repaired is None  # a server that does not send them


def test_a_reconstruction_answer_types_its_closeness_and_repairs():
    closeness = [{"rms": 0.002, "max": 0.01, "max_at": 3}, {"rms": 0.03, "max": 0.05, "max_at": 1}]
    body = {"curves": [CURVE, CURVE[:3]], "mse": [0.5, 0.25], "closeness": closeness, "repaired": [False, True]}
    got = calls.parse_reconstructed(orjson.dumps(body), MODEL)
    assert isinstance(got.closeness, Closeness) and got.closeness.json() == closeness
    assert got.closeness.max_at.dtype == np.int64 and got.closeness.rms.tolist() == [0.002, 0.03]
    assert got.repaired is not None and got.repaired.dtype == bool and got.repaired.tolist() == [False, True]


def test_an_encoding_answer_with_and_without_closeness():
    body = {"mean": [[0.1, 0.2]], "log_var": [[-1.0, -2.0]], "frames": None}
    assert calls.parse_encoded(orjson.dumps(body), MODEL).closeness is None
    closeness = [{"rms": 0.004, "max": 0.02, "max_at": 2}]
    got = calls.parse_encoded(orjson.dumps({**body, "closeness": closeness}), MODEL)
    assert isinstance(got, Encoded) and got.closeness is not None and got.closeness.json() == closeness


def test_an_interpolation_answer_types_its_validity_repairs_and_ends():
    body = {"curves": [CURVE, CURVE, CURVE], "weights": [[1, 0], [0.5, 0.5], [0, 1]], "frames": None}
    got = calls.parse_interpolated(orjson.dumps(body), MODEL)
    assert isinstance(got, Interpolated) and got.valid is None and got.repaired is None and got.ends is None
    ends = [{"rms": 0.01, "max": 0.02, "max_at": 0}, {"rms": 0.03, "max": 0.04, "max_at": 3}]
    sent = {**body, "valid": [True, False, True], "repaired": [False, True, False], "ends": ends}
    got = calls.parse_interpolated(orjson.dumps(sent), MODEL)
    assert got.valid is not None and got.valid.dtype == bool and got.valid.tolist() == [True, False, True]
    assert got.repaired is not None and got.repaired.tolist() == [False, True, False]
    assert got.ends is not None and len(got.ends) == 2 and got.ends.json() == ends
    assert got.weights.dtype == np.float64 and got.weights.tolist() == [[1, 0], [0.5, 0.5], [0, 1]]


def test_a_sample_answer_types_its_fields():
    body = orjson.dumps(
        {"curves": [CURVE], "latents": [[0.1, 0.2]], "seed": 7, "prior": "learned", "rejected": 2, "invalid": 0}
    )
    got = calls.parse_sampled(body, MODEL)
    assert isinstance(got, Sampled) and got.stacked().shape == (1, 4, 2)
    assert (got.seed, got.prior, got.rejected, got.invalid) == (7, "learned", 2, 0)
    assert got.latents.tolist() == [[0.1, 0.2]]


def test_an_augment_page_and_an_npy_chunk():
    page = {"curves": [CURVE], "sources": [[2, 0]], "weights": [[0.75, 0.25]], "seed": 3, "offset": 40}
    got = calls.parse_augmented(orjson.dumps(page), MODEL)
    assert isinstance(got, Augmented) and (got.seed, got.offset) == (3, 40)
    assert got.sources.dtype == np.int64 and got.sources.tolist() == [[2, 0]] and got.weights.tolist() == [[0.75, 0.25]]
    assert got.redrawn is None and got.invalid is None  # not sent: not a made-up 0
    counted = calls.parse_augmented(orjson.dumps({**page, "redrawn": 4, "invalid": 1}), MODEL)
    assert (counted.redrawn, counted.invalid) == (4, 1)
    buf = io.BytesIO()
    np.save(buf, np.ones((2, 4, 2), np.float32))
    assert calls.parse_npy(buf.getvalue(), MODEL).shape == (2, 4, 2)


def test_a_decode_call_sends_latents_and_parses_curves():
    call = calls.decode_call(np.zeros((1, 3)), {"n_points": 5})
    assert call.path == "/decode" and orjson.loads(call.body()) == {"latents": [[0.0, 0.0, 0.0]], "n_points": 5}
    got = call.parse(orjson.dumps({"curves": [CURVE]}), MODEL)
    assert type(got) is Curves and got.stacked().shape == (1, 4, 2) and got.curve.tolist() == CURVE


def test_a_fit_answer_is_one_typed_fit_per_curve_and_writes_back_the_same_body():
    fit = {
        "control_points": [[0, 0], [1, 2], [2, 1], [3, 3]],
        "knots": [0, 0, 0, 0, 1, 1, 1, 1],
        "degree": 3,
        "n_ctrl": 4,
        "rms_error": 0.0,
        "max_error": 0.0,
    }
    body = {"fits": [fit, {**fit, "curve": [[0, 0], [1.5, 1.5], [3, 3]]}]}
    call = calls.fit_call([CURVE, CURVE], {"n_ctrl": 4})
    got = call.parse(orjson.dumps(body), MODEL, calls.NO_HEADERS)
    assert isinstance(got, Fitted) and got.model == MODEL and all(isinstance(f, BSplineFit) for f in got.fits)
    first, second = got.fits
    assert first.control_points.shape == (4, 2) and first.knots.shape == (8,) and (first.degree, first.n_ctrl) == (3, 4)
    assert first.curve is None and second.curve is not None and second.curve.shape == (3, 2)
    assert got.json() == body  # what `curve-vae fit` writes
    with pytest.raises(ValueError, match="this one has 2 fits"):
        _ = got.spline


def test_a_revolve_answer_is_the_file_with_what_its_headers_say():
    call = calls.revolve_call(CURVE, {"format": "stl"})
    headers = httpx.Headers(
        {"Content-Type": "model/stl", "X-Mesh-Vertices": "12", "X-Mesh-Faces": "20", "X-Mesh-Closed": "true"}
    )
    got = call.parse(b"solid", MODEL, headers)
    assert isinstance(got, Revolved) and got.data == b"solid" and bytes(got) == b"solid"
    assert (got.format, got.media_type, got.n_vertices, got.n_faces, got.closed) == ("stl", "model/stl", 12, 20, True)
    bare = calls.revolve_call(CURVE, {}).parse(b"v 0 0 0\n", MODEL, calls.NO_HEADERS)
    assert (bare.format, bare.n_vertices, bare.n_faces, bare.closed) == ("obj", None, None, None)  # what was asked
