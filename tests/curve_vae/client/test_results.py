"""curve_vae.client.results: the model an answer names (the files that decide its answers, not the torch weights),
and curves as one array where they share a length, else a list."""

from __future__ import annotations

import numpy as np

from curve_vae.client.results import ModelRef, curves_of

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


def test_curves_of_one_length_are_one_array():
    got = curves_of([[[0, 0], [1, 1], [2, 0]], [[5, 5], [6, 6], [7, 5]]])
    assert isinstance(got, np.ndarray) and got.shape == (2, 3, 2) and got.dtype == np.float64
    assert got[1, 2].tolist() == [7.0, 5.0]


def test_curves_of_other_lengths_are_a_list_and_flat_points_pair_up():
    a, b = curves_of([[0, 0, 1, 1, 2, 0], [[5, 5], [6, 6]]])
    assert a.tolist() == [[0, 0], [1, 1], [2, 0]] and b.tolist() == [[5, 5], [6, 6]]


def test_no_curves_are_an_empty_array():
    assert curves_of([]).shape == (0, 0, 2)
