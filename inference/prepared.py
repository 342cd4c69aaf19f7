"""A caller's curve as the model read it (`ReadCurve`: its frame, the model-plane points the encoder saw, its latent,
the decoded spline and where the caller's points sit on it), and a batch of them (`Prepared`). The encoding cache
keeps ReadCurves (`EncodingCache`, below); the runtime fills in what a call needs (the decoding, the placement) and
maps results back."""

from __future__ import annotations

import hashlib
import threading
from collections import OrderedDict
from collections.abc import Sequence
from dataclasses import dataclass, replace
from typing import Any, ClassVar

import numpy as np

from curve_vae.geometry import Frame


@dataclass(frozen=True)
class ReadCurve:
    """One caller curve brought to the model and through it."""

    frame: Frame | None  # the caller's frame and pose; None for frame "model"
    model: np.ndarray  # (n_points, 2) float32: what the encoder read, in the model plane
    fraction: np.ndarray | None  # where each caller point sits along `model`'s points, in [0, 1]; None: the same
    mean: np.ndarray  # (latent_dim,) the latent (with refine, the fitted one)
    log_var: np.ndarray  # (latent_dim,)
    decoded: np.ndarray | None = None  # (n_points, 2) the decoding of `mean`, model plane
    ctrl: np.ndarray | None = None  # (n_ctrl, 2) its control points, with a B-spline head
    params: np.ndarray | None = None  # (n_points,) its points' spline parameters, with a head that learns them
    feet: np.ndarray | None = None  # with closest placement or refine: each caller point's spline parameter
    repair: np.ndarray | None = None  # (n_ctrl, 2) float64: how `ctrl` was moved to uncross the answer (untangling)
    pin: np.ndarray | None = None  # (n_ctrl, 2) float64: how `ctrl` was moved onto the input's ends (inference.placing)
    distance: float | None = None  # the decoding's squared distance from the input in the model plane (Reader._decoded)

    ARRAYS: ClassVar[tuple[str, ...]] = (
        "model", "fraction", "mean", "log_var", "decoded", "ctrl", "params", "feet", "repair", "pin"
    )  # fmt: skip

    @property
    def decoded_yet(self) -> bool:
        return self.decoded is not None

    def nbytes(self) -> int:
        parts = (getattr(self, name) for name in self.ARRAYS)
        return sum(p.nbytes for p in parts if p is not None) + 200

    def owned(self) -> ReadCurve:
        """This row with arrays of its own: a row sliced out of a batch's arrays keeps the whole batch alive, so what
        is kept (the encoding cache) keeps copies, and `nbytes` is then the memory it holds."""
        # Any: mypy checks a **mapping against every field (frame too); these names are ARRAYS', all ndarray | None
        views: dict[str, Any] = {
            name: np.array(a, copy=True)
            for name in self.ARRAYS
            if (a := getattr(self, name)) is not None and a.base is not None
        }
        return replace(self, **views) if views else self

    def with_decoding(
        self,
        decoded: np.ndarray,
        ctrl: np.ndarray | None,
        params: np.ndarray | None,
        feet: np.ndarray | None,
        distance: float | None = None,
    ) -> ReadCurve:
        return replace(
            self, decoded=decoded, ctrl=ctrl, params=params, feet=feet, repair=None, pin=None, distance=distance
        )

    def moved_to(self, mean: np.ndarray) -> ReadCurve:
        """This reading with another latent, not decoded yet (a look again, a fit)."""
        return replace(
            self, mean=mean, decoded=None, ctrl=None, params=None, feet=None, repair=None, pin=None, distance=None
        )


@dataclass(frozen=True)
class Prepared:
    """A batch of caller curves and how the model read each."""

    inputs: list[np.ndarray]  # the caller's curves, float64
    rows: list[ReadCurve]
    ends_kept: bool = True  # answers start and end where their inputs do, so do curves mixed of them (placing)

    @property
    def frames(self) -> list[Frame | None]:
        return [r.frame for r in self.rows]

    @property
    def mean(self) -> np.ndarray:
        return _stack([r.mean for r in self.rows])

    @property
    def log_var(self) -> np.ndarray:
        return _stack([r.log_var for r in self.rows])

    @property
    def fractions(self) -> list[np.ndarray | None]:
        return [r.fraction for r in self.rows]

    @property
    def feet(self) -> list[np.ndarray | None]:
        return [r.feet for r in self.rows]

    @property
    def placed(self) -> bool:
        """Whether each caller point has a spline parameter (closest placement or refine)."""
        return bool(self.rows) and all(r.feet is not None for r in self.rows)


def _stack(parts: Sequence[np.ndarray]) -> np.ndarray:
    return np.stack(parts) if parts else np.zeros((0, 0), np.float32)


# The encoding cache: a curve read once is not read again. The page re-posts its two or three curves at every
# slider move, an augmentation pipeline its seed curves with every page, a client its batch after a dropped
# connection; each finds its curves here — frame, latent, decoding and placement — and skips the encoder.
#
# Keyed by the curve's exact bytes (float64 points) and the reading (frame, pose, spacing, refine, placement): the
# same points read the same way give the same ReadCurve, so a hit returns exactly what a miss would compute. Bounded
# by the bytes of what it holds (least recently used out first) and safe to share between inference threads.
#

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
