"""The encoding cache: a curve read once is not read again. The page re-posts its two or three curves at every
slider move, an augmentation pipeline its seed curves with every page, a client its batch after a dropped
connection; each finds its curves here — frame, latent, decoding and placement — and skips the encoder.

Keyed by the curve's exact bytes (float64 points) and the reading (frame, pose, spacing, refine, placement): the
same points read the same way give the same ReadCurve, so a hit returns exactly what a miss would compute. Bounded
by the bytes of what it holds (least recently used out first) and safe to share between inference threads.
"""

from __future__ import annotations

import hashlib
import threading
from collections import OrderedDict

import numpy as np

from curve_vae.inference.prepared import ReadCurve

#: The default bound: about 20,000 curves of 161 points with their decodings.
DEFAULT_CACHE_BYTES = 64 << 20


class EncodingCache:
    """ReadCurves by (curve bytes, reading), least recently used evicted beyond `max_bytes` (0: keeps nothing)."""

    def __init__(self, max_bytes: int = DEFAULT_CACHE_BYTES) -> None:
        self.max_bytes = max_bytes
        self._rows: OrderedDict[bytes, ReadCurve] = OrderedDict()
        self._bytes = 0
        self._lock = threading.Lock()
        self.hits = 0
        self.misses = 0

    @staticmethod
    def key(points: np.ndarray, reading: str) -> bytes:
        pts = np.ascontiguousarray(points, np.float64)
        h = hashlib.blake2b(pts.tobytes(), digest_size=20)
        h.update(f"{pts.shape}|{reading}".encode())
        return h.digest()

    def get(self, key: bytes) -> ReadCurve | None:
        with self._lock:
            row = self._rows.get(key)
            if row is None:
                self.misses += 1
                return None
            self._rows.move_to_end(key)
            self.hits += 1
            return row

    def put(self, key: bytes, row: ReadCurve) -> None:
        size = row.nbytes()
        if size > self.max_bytes:
            return
        row = row.owned()  # not a view into the request's batch arrays, which would stay alive with it
        with self._lock:
            old = self._rows.pop(key, None)
            if old is not None:
                self._bytes -= old.nbytes()
            self._rows[key] = row
            self._bytes += size
            while self._bytes > self.max_bytes:
                _, evicted = self._rows.popitem(last=False)
                self._bytes -= evicted.nbytes()

    def clear(self) -> None:
        with self._lock:
            self._rows.clear()
            self._bytes = 0

    @property
    def size(self) -> int:
        """Bytes held."""
        return self._bytes

    def __len__(self) -> int:
        return len(self._rows)

    def stats(self) -> dict[str, int]:
        return {"entries": len(self), "bytes": self._bytes, "max_bytes": self.max_bytes, "hits": self.hits,
                "misses": self.misses}  # fmt: skip
