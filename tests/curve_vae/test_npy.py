"""curve_vae.npy: a .npy streamed as its header then chunks is, byte for byte, the file numpy.save writes of the
whole float32 array; chunks that do not fill or fit the promised shape are refused."""

from __future__ import annotations

import io

import numpy as np
import pytest

from curve_vae.errors import InvalidInput
from curve_vae.npy import DTYPE, chunk_bytes, npy_chunks, npy_header, npy_size


def _saved(a: np.ndarray) -> bytes:
    buf = io.BytesIO()
    np.save(buf, a, allow_pickle=False)
    return buf.getvalue()


@pytest.mark.parametrize(
    "shape",
    [pytest.param((0, 161, 2), id="empty"), pytest.param((7, 161, 2), id="curves"), pytest.param((3, 32), id="2d")],
)
def test_the_header_is_numpys_and_reads_back_the_shape(shape):
    header = npy_header(shape)
    assert header == _saved(np.zeros(shape, DTYPE))[: len(header)]
    f = io.BytesIO(header)
    assert np.lib.format.read_magic(f) == (1, 0)
    assert np.lib.format.read_array_header_1_0(f) == (shape, False, np.dtype("<f4"))
    assert len(header) % 64 == 0  # numpy aligns the data


@pytest.mark.parametrize("shape", [(0, 161, 2), (7, 161, 2), (3, 32)], ids=["empty", "curves", "2d"])
def test_the_size_is_the_saved_files(shape):
    assert npy_size(shape) == len(_saved(np.zeros(shape, DTYPE)))
    assert npy_size(shape, np.dtype("<f8")) == len(_saved(np.zeros(shape, "<f8")))


def test_header_and_chunks_are_the_saved_float32_array():
    a = np.random.default_rng(1).normal(size=(10, 6, 2))  # float64 in: float32 out, as the model's precision
    streamed = b"".join(npy_chunks(a.shape, [a[:4], a[4:5], a[5:]]))
    assert streamed == _saved(a.astype("<f4"))
    np.testing.assert_array_equal(np.load(io.BytesIO(streamed)), a.astype(np.float32))


def test_a_chunk_is_its_rows_bytes_in_c_order():
    a = np.arange(12, dtype=np.float64).reshape(3, 2, 2)
    fortran = np.asfortranarray(a)
    assert chunk_bytes(fortran, (5, 2, 2)) == np.arange(12, dtype="<f4").tobytes()


@pytest.mark.parametrize(
    ("chunks", "message"),
    [
        pytest.param([np.zeros((2, 6, 2))], r"chunks gave 2 rows, the header promised 4", id="too-few"),
        pytest.param([np.zeros((3, 6, 2))] * 2, r"chunks gave 6 rows, the header promised 4", id="too-many"),
        pytest.param([np.zeros((4, 5, 2))], r"chunk of shape \(4, 5, 2\) does not fit an array of shape \(4, 6, 2\)",
                     id="other-points"),
    ],
)  # fmt: skip
def test_chunks_that_break_the_promised_shape_are_refused(chunks, message):
    with pytest.raises(InvalidInput, match=message):
        b"".join(npy_chunks((4, 6, 2), chunks))
