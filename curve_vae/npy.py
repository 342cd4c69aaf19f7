"""Streaming .npy files: the header for the known final shape first, then the data in chunks.

A batch of any size can be sent or written this way with memory bounded by one chunk;
`numpy.load` reads the result like any .npy file. Curves are float32, little-endian.
"""

from __future__ import annotations

import io
import math
from collections.abc import Iterable, Iterator

import numpy as np

from curve_vae.errors import InvalidInput

DTYPE = np.dtype("<f4")  # float32, the model's own precision: half the bytes of float64
MEDIA_TYPE = "application/octet-stream"


def npy_header(shape: tuple[int, ...], dtype: np.dtype = DTYPE) -> bytes:
    """The .npy header (format 1.0) of a C-ordered array of `shape` and `dtype`."""
    buf = io.BytesIO()
    header = {"descr": np.lib.format.dtype_to_descr(dtype), "fortran_order": False, "shape": tuple(shape)}
    np.lib.format.write_array_header_1_0(buf, header)
    return buf.getvalue()


def npy_size(shape: tuple[int, ...], dtype: np.dtype = DTYPE) -> int:
    """Bytes of the whole .npy file: header and data."""
    return len(npy_header(shape, dtype)) + math.prod(shape) * dtype.itemsize


def npy_chunks(shape: tuple[int, ...], chunks: Iterable[np.ndarray], dtype: np.dtype = DTYPE) -> Iterator[bytes]:
    """Header, then each chunk's bytes; the chunks must fill `shape` along its first axis, in order."""
    yield npy_header(shape, dtype)
    rows = 0
    for chunk in chunks:
        rows += len(chunk)
        yield chunk_bytes(chunk, shape, dtype)
    if rows != shape[0]:
        raise InvalidInput(f"chunks gave {rows} rows, the header promised {shape[0]}")


def chunk_bytes(chunk: np.ndarray, shape: tuple[int, ...], dtype: np.dtype = DTYPE) -> bytes:
    """The data bytes of a chunk of rows of an array of `shape`."""
    a = np.ascontiguousarray(chunk, dtype=dtype)
    if a.shape[1:] != tuple(shape[1:]):
        raise InvalidInput(f"chunk of shape {a.shape} does not fit an array of shape {shape}")
    return a.tobytes()
