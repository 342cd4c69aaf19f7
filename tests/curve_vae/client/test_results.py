"""curve_vae.client.results: the model an answer names (the files that decide its answers, not the torch weights);
curves always a list of (n_i, 2) arrays, stacked where they share a length, the one curve of an answer of one; how
close an answer came (Closeness) parsed from the service's JSON and written back."""

from __future__ import annotations

import numpy as np
import pytest

from curve_vae.client.results import Closeness, Curves, ModelRef

INFO = {
    "name": "curve-vae",
    "version": "spline31",
    "service_version": "0.15.0",
    "latent_dim": 32,
    "files": {
        "encoder.onnx": {"sha256": "e" * 64, "bytes": 10},
        "decoder.onnx": {"sha256": "d" * 64, "bytes": 10},
        "prior.npz": {"sha256": "p" * 64, "bytes": 10},
        "vae.pt": {"sha256": "t" * 64, "bytes": 10},
    },
}


MODEL = ModelRef("m", "1", "0.15.0", {})


def test_a_model_ref_holds_the_files_that_decide_answers():
    ref = ModelRef.from_info(INFO, "http://host:8000")
    assert ref.sha256 == {"encoder.onnx": "e" * 64, "decoder.onnx": "d" * 64, "prior.npz": "p" * 64}
    assert ref.json() == {
        "name": "curve-vae",
        "version": "spline31",
        "service_version": "0.15.0",
        "sha256": ref.sha256,
        "url": "http://host:8000",
    }
    assert ModelRef(**ref.json()) == ref  # what a manifest saves makes the same ref


def test_a_model_ref_of_an_info_without_files_is_empty_not_an_error():
    assert ModelRef.from_info({}) == ModelRef("", "", "", {}, "")


def test_curves_come_back_as_a_list_of_float64_arrays_whatever_their_lengths():
    same = Curves(MODEL, [[[0, 0], [1, 1], [2, 0]], [[5, 5], [6, 6], [7, 5]]])
    ragged = Curves(MODEL, [[[0, 0], [1, 1], [2, 0]], [[5, 5], [6, 6]]])
    for got, lengths in ((same, [3, 3]), (ragged, [3, 2])):
        assert type(got.curves) is list and [c.shape for c in got.curves] == [(n, 2) for n in lengths]
        assert all(c.dtype == np.float64 for c in got.curves)
    assert same.curves[1][2].tolist() == [7.0, 5.0] and ragged.curves[1].tolist() == [[5, 5], [6, 6]]


def test_curves_of_one_length_stack_and_others_say_why_not():
    same = Curves(MODEL, [[[0, 0], [1, 1], [2, 0]], [[5, 5], [6, 6], [7, 5]]])
    stacked = same.stacked()
    assert stacked.shape == (2, 3, 2) and stacked.dtype == np.float64
    np.testing.assert_array_equal(stacked[1], same.curves[1])
    ragged = Curves(MODEL, [[[0, 0], [1, 1], [2, 0]], [[5, 5], [6, 6]]])
    with pytest.raises(ValueError, match=r"curves of 2, 3 points do not stack.*n_points"):
        ragged.stacked()
    assert Curves(MODEL, []).stacked().shape == (0, 0, 2)


def test_an_array_of_curves_becomes_views_of_it_its_dtype_kept():
    """A .npy chunk (augment_chunks): float32 as streamed, no copy."""
    chunk = np.arange(24, dtype=np.float32).reshape(3, 4, 2)
    got = Curves(MODEL, chunk)
    assert type(got.curves) is list and len(got.curves) == 3
    assert all(c.dtype == np.float32 and np.shares_memory(c, chunk) for c in got.curves)
    np.testing.assert_array_equal(got.stacked(), chunk)


def test_the_curve_of_an_answer_of_one_and_of_others():
    one = Curves(MODEL, [[[0, 0], [1, 2], [3, 1]]])
    assert one.curve.tolist() == [[0, 0], [1, 2], [3, 1]]
    for count in (0, 2):
        with pytest.raises(ValueError, match=rf"\.curve is the curve of an answer of one; this one has {count} curves"):
            _ = Curves(MODEL, [[[0, 0], [1, 2]]] * count).curve


def test_closeness_parses_to_three_arrays_and_back():
    sent = [{"rms": 0.001, "max": 0.004, "max_at": 17}, {"rms": 0.5, "max": 1.25, "max_at": 0}]
    got = Closeness.from_json(sent)
    assert len(got) == 2 and got.json() == sent
    assert got.rms.dtype == np.float64 and got.max.dtype == np.float64 and got.max_at.dtype == np.int64
    assert got.max_at.tolist() == [17, 0] and got.rms.tolist() == [0.001, 0.5]
    assert Closeness.parse(None) is None and len(Closeness.parse([])) == 0


def test_a_figure_beyond_float64_is_nan_not_an_error():
    got = Closeness.from_json([{"rms": None, "max": None, "max_at": 3}])
    assert np.isnan(got.rms[0]) and np.isnan(got.max[0]) and got.max_at.tolist() == [3]
