"""inference.prepared: a caller's curve as the model read it (`ReadCurve`) and a batch of them (`Prepared`) — what the
encoding cache measures and keeps (own copies, not views of a batch), and the batch's stacked views."""

import numpy as np

from curve_vae.geometry import Frame
from curve_vae.inference.prepared import Prepared, ReadCurve


def _row(batch: np.ndarray | None = None, i: int = 0, *, feet: np.ndarray | None = None) -> ReadCurve:
    model = np.zeros((161, 2), np.float32) if batch is None else batch[i]
    return ReadCurve(
        Frame((1.0, 2.0), 3.0), model, None, np.full(32, float(i), np.float32), np.zeros(32, np.float32), feet=feet
    )


def test_nbytes_counts_every_array_it_holds_plus_a_fixed_overhead():
    row = _row()
    assert row.nbytes() == 161 * 2 * 4 + 32 * 4 * 2 + 200
    decoded = row.with_decoding(np.zeros((161, 2), np.float32), np.zeros((31, 2), np.float32), None, np.zeros(90))
    assert decoded.nbytes() == row.nbytes() + 161 * 2 * 4 + 31 * 2 * 4 + 90 * 8
    assert decoded.decoded_yet and not row.decoded_yet
    assert decoded.frame == row.frame and decoded.params is None  # the rest is kept


def test_owned_copies_rows_sliced_from_a_batch_and_keeps_rows_that_own_their_arrays():
    batch = np.arange(3 * 161 * 2, dtype=np.float32).reshape(3, 161, 2)
    row = _row(batch, 1)
    assert np.shares_memory(row.model, batch)
    own = row.owned()
    assert not np.shares_memory(own.model, batch)  # the cache holds this row, not the whole batch
    np.testing.assert_array_equal(own.model, batch[1])
    assert own.mean is row.mean  # already its own: not copied again
    lone = _row()
    assert lone.owned() is lone  # nothing to copy: the same row


def test_a_batchs_views_stack_its_rows():
    rows = [_row(i=i) for i in range(3)]
    prep = Prepared([np.zeros((5, 2))] * 3, rows)
    assert prep.mean.shape == (3, 32) and prep.log_var.shape == (3, 32)
    np.testing.assert_array_equal(prep.mean[:, 0], [0.0, 1.0, 2.0])
    assert prep.frames == [r.frame for r in rows] and prep.fractions == [None] * 3


def test_a_batch_is_placed_only_when_every_curve_has_its_feet():
    some = Prepared([np.zeros((5, 2))] * 2, [_row(feet=np.linspace(0, 1, 5)), _row()])
    every = Prepared([np.zeros((5, 2))] * 2, [_row(feet=np.linspace(0, 1, 5))] * 2)
    assert not some.placed and every.placed
    assert some.feet[1] is None
    assert not Prepared([], []).placed  # nothing placed when there is nothing


def test_an_empty_batch_has_empty_latents():
    empty = Prepared([], [])
    assert empty.mean.shape == (0, 0) and empty.log_var.shape == (0, 0) and empty.frames == []
