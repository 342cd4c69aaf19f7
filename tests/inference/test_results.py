"""inference.results: the runtime's result objects — a spline as the API writes it, which splines a result carries,
and the empty defaults of the result kinds that extend `Curves`."""

import json

import numpy as np
import pytest

from curve_vae.geometry import Frame, clamped_uniform_knots
from curve_vae.inference.results import Augmented, Curves, Interpolation, Sampled, Spline, head_splines


def _spline(shift: float = 0.0) -> Spline:
    ctrl = np.array([[0.0, 0.0], [1.0, 2.0], [3.0, 2.0], [4.0, 0.0], [5.0, -1.0]]) + shift
    return Spline(ctrl, clamped_uniform_knots(5), 3, np.array([0.0, 0.5, 1.0]))


def test_a_spline_as_json_is_plain_lists_that_round_trip():
    s = _spline()
    body = s.json()
    assert set(body) == {"control_points", "knots", "degree", "params"}
    # plain Python numbers: the standard json module writes it, and reading it back gives the arrays
    back = json.loads(json.dumps(body))
    np.testing.assert_array_equal(back["control_points"], s.control_points)
    np.testing.assert_array_equal(back["knots"], [0, 0, 0, 0, 0.5, 1, 1, 1, 1])
    assert back["degree"] == 3 and back["params"] == [0.0, 0.5, 1.0]


def test_head_splines_are_every_curves_from_a_model_with_a_head_and_none_without():
    splines = [_spline(), _spline(1.0)]
    assert head_splines(splines, True) == splines
    assert head_splines([None, None], False) is None
    assert head_splines([], True) == []  # no curves asked: no splines, not "no head"


@pytest.mark.parametrize(
    "kind, empty",
    [
        (Interpolation, {"weights": (0, 0)}),
        (Sampled, {"latents": (0, 0)}),
        (Augmented, {"sources": (0, 0), "weights": (0, 0)}),
    ],
    ids=["interpolation", "sampled", "augmented"],
)
def test_the_kinds_of_curves_default_to_empty_arrays_of_their_own(kind, empty):
    a = kind(np.zeros((1, 4, 2)), [Frame((0.0, 0.0), 1.0)])
    b = kind(np.zeros((1, 4, 2)), [None])
    assert isinstance(a, Curves) and a.splines is None
    for name, shape in empty.items():
        assert getattr(a, name).shape == shape
        assert getattr(a, name) is not getattr(b, name)  # a default factory: never one array shared by all results


def test_sampled_and_augmented_bookkeeping_defaults():
    s = Sampled(np.zeros((0, 4, 2)), [])
    assert (s.prior, s.seed, s.offset, s.rejected, s.invalid) == ("learned", 0, 0, 0, 0)
    assert Augmented(np.zeros((0, 4, 2)), []).sources.dtype == np.int64  # indices of seed curves
