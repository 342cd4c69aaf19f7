"""curve_vae.client.inputs: one curve told from a batch, whatever holds it (an (n, 2) array, a list of [x, y] pairs,
a list of point arrays, something numpy reads as an array), and sent as a batch of one; a method that mixes curves
refuses one curve, naming itself and what it needs."""

from __future__ import annotations

import numpy as np
import pytest

from curve_vae.client.inputs import as_batch, is_one_curve
from curve_vae.errors import InvalidInput

CURVE = [[0.0, 0.0], [1.0, 2.0], [2.0, 1.5], [3.0, 0.0]]


class ArrayLike:
    """Neither a sequence nor an array, but read by numpy as one (a DataFrame, a tensor)."""

    def __init__(self, values: object) -> None:
        self.values = np.asarray(values)

    def __array__(self, dtype=None, copy=None) -> np.ndarray:
        return self.values if dtype is None else self.values.astype(dtype)


ONE = {
    "array": np.array(CURVE),
    "np.c_": np.c_[[0, 1, 2, 3], [0, 2, 1.5, 0]],
    "ints": np.array(CURVE, np.int64),
    "list of pairs": CURVE,
    "tuple of tuples": tuple(tuple(p) for p in CURVE),
    "list of point arrays": [np.array(p) for p in CURVE],
    "numpy scalars": [[np.float32(x), np.float32(y)] for x, y in CURVE],
    "one point": [[1.0, 2.0]],
    "two points as an array": np.array(CURVE[:2]),
    "array-like": ArrayLike(CURVE),
}
BATCHES = {  # (the batch, how many curves it holds)
    "(B, n, 2) array": (np.array([CURVE, CURVE]), 2),
    "(1, n, 2) array": (np.array([CURVE]), 1),
    "list of curves": ([CURVE, CURVE[:3]], 2),
    "list of one curve": ([CURVE], 1),
    "list of arrays": ([np.array(CURVE), np.array(CURVE[:3])], 2),
    "curves of two points": ([CURVE[:2], CURVE[2:]], 2),
    "array-like batch": (ArrayLike([CURVE, CURVE, CURVE]), 3),
    "empty list": ([], 0),
    "empty array": (np.zeros((0, 2)), 0),
}


@pytest.mark.parametrize("curve", ONE.values(), ids=ONE.keys())
def test_one_curve_is_sent_as_a_batch_of_one(curve):
    got = as_batch(curve, "reconstruct")
    assert len(got) == 1
    np.testing.assert_array_equal(np.asarray(got[0], np.float64), np.asarray(curve, np.float64))


@pytest.mark.parametrize(("curves", "count"), BATCHES.values(), ids=BATCHES.keys())
def test_a_batch_is_sent_as_it_is(curves, count):
    assert not is_one_curve(curves) and len(as_batch(curves, "reconstruct")) == count


@pytest.mark.parametrize("not_points", ["xy", b"xy", [["0", "1"], ["2", "3"]], np.array([["a", "b"]]), 7])
def test_strings_and_other_things_are_not_points(not_points):
    assert not is_one_curve(not_points)


@pytest.mark.parametrize("method", ["interpolate", "augment"])
def test_a_method_that_mixes_curves_refuses_one_naming_itself(method):
    with pytest.raises(InvalidInput, match=rf"{method} needs at least 2 curves, got one curve \(4 \[x, y\] points\)"):
        as_batch(np.array(CURVE), method, at_least=2)
    assert len(as_batch([CURVE, CURVE], method, at_least=2)) == 2  # a batch passes: its count is the server's to judge


def test_a_dataframe_of_x_and_y_is_one_curve():
    pd = pytest.importorskip("pandas")
    frame = pd.DataFrame({"x": [0.0, 1.0, 2.0, 3.0], "y": [0.0, 2.0, 1.5, 0.0]})
    (got,) = as_batch(frame, "reconstruct")
    np.testing.assert_array_equal(np.asarray(got), np.array(CURVE))
