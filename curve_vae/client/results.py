"""What the client's calls return: numpy arrays by name, and the model that made them (`ModelRef`), so a saved batch
says what made it.

Curves come back one way only: `.curves` is a list of (n_i, 2) arrays, one per curve, whatever their lengths
(float64 as JSON carries them; float32 in `augment_chunks`' .npy chunks, as the server streams them). `.stacked()`
makes them one (B, n, 2) array where they share a length and says why not where they don't; `.curve` is the one
curve of a one-curve answer (a call given one curve is answered as a batch of one). A field the server did not send
(an older server, or a field of another output) is None, never a made-up default.

Figures of how close an answer came to its input (`Closeness`) are unitless: fractions of each input curve's
bounding-box diagonal.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np


@dataclass(frozen=True)
class ModelRef:
    """The model a server answered with: its name and version, the service's version, and the sha256 of the files
    that decide its answers (both graphs and the prior)."""

    name: str
    version: str
    service_version: str
    sha256: dict[str, str]
    url: str = ""

    @classmethod
    def from_info(cls, info: dict[str, Any], url: str = "") -> ModelRef:
        files = info.get("files") or {}
        return cls(
            name=str(info.get("name", "")),
            version=str(info.get("version", "")),
            service_version=str(info.get("service_version", "")),
            sha256={k: v["sha256"] for k, v in files.items() if k != "vae.pt"},
            url=url,
        )

    def json(self) -> dict[str, Any]:
        return {
            "name": self.name,
            "version": self.version,
            "service_version": self.service_version,
            "sha256": self.sha256,
            "url": self.url,
        }


def _float_curve(c: Any) -> bool:
    return isinstance(c, np.ndarray) and c.ndim == 2 and c.shape[1] == 2 and c.dtype.kind == "f"


def curve_list(data: Any) -> list[np.ndarray]:
    """Curves as a list of (n_i, 2) arrays: float arrays as they are (a (B, n, 2) array's curves as views of it),
    anything else (JSON's nested lists) as float64."""
    if data is None:
        return []
    if isinstance(data, np.ndarray) and data.ndim == 3 and data.shape[2] == 2 and data.dtype.kind == "f":
        return list(data)
    if isinstance(data, list) and all(_float_curve(c) for c in data):
        return list(data)  # a list of its own: the caller's may change
    try:  # curves of one length: one conversion, then views
        whole = np.asarray(data, np.float64)
    except ValueError:  # lengths differ
        whole = None
    if whole is not None and whole.ndim == 3 and whole.shape[2] == 2:
        return list(whole)
    return [np.asarray(c, np.float64).reshape(-1, 2) for c in data]


def stacked(curves: Sequence[np.ndarray]) -> np.ndarray:
    """Curves of one length as one (B, n, 2) array; ValueError naming the lengths where they differ."""
    if not len(curves):
        return np.zeros((0, 0, 2))
    lengths = sorted({len(c) for c in curves})
    if len(lengths) > 1:
        shown = ", ".join(map(str, lengths[:5])) + (", …" if len(lengths) > 5 else "")
        raise ValueError(
            f"curves of {shown} points do not stack into one array: ask for n_points to have them all one length, "
            "or use .curves, a list of (n_i, 2) arrays"
        )
    return np.stack(curves)


def only(items: Sequence[Any], what: str, plural: str) -> Any:
    """The one item of a one-item answer; ValueError where there are more or none."""
    if len(items) != 1:
        raise ValueError(f".{what} is the {what} of an answer of one; this one has {len(items)} {plural}")
    return items[0]


def _floats(values: Sequence[Any]) -> np.ndarray:
    """float64, a null (a figure beyond float64 in JSON) as nan."""
    return np.array([np.nan if v is None else v for v in values], np.float64)


@dataclass(frozen=True)
class Closeness:
    """How close each answer came to its input, relative to the input's size: the RMS (`rms`) and the largest
    (`max`) distance over the input's points, each ÷ the input's bounding-box diagonal, and the index of that
    farthest point (`max_at`); (B,) arrays, one entry per curve. 0.001 is 0.1% of the curve's diagonal."""

    rms: np.ndarray  # (B,) float64
    max: np.ndarray  # (B,) float64
    max_at: np.ndarray  # (B,) int64

    @classmethod
    def from_json(cls, items: Sequence[dict[str, Any]]) -> Closeness:
        return cls(
            _floats([c["rms"] for c in items]),
            _floats([c["max"] for c in items]),
            np.array([c["max_at"] for c in items], np.int64).reshape(-1),
        )

    @classmethod
    def parse(cls, items: Sequence[dict[str, Any]] | None) -> Closeness | None:
        """The answer's field, or None where it was absent."""
        return None if items is None else cls.from_json(items)

    def __len__(self) -> int:
        return len(self.rms)

    def json(self) -> list[dict[str, Any]]:
        """As the service sends it: one {"rms", "max", "max_at"} per curve."""
        return [
            {"rms": float(r), "max": float(m), "max_at": int(i)} for r, m, i in zip(self.rms, self.max, self.max_at)
        ]


def bools(values: Sequence[Any] | None) -> np.ndarray | None:
    """A (B,) bool array of the answer's field, or None where it was absent."""
    return None if values is None else np.array(values, bool).reshape(-1)


@dataclass(frozen=True)
class Result:
    """Every answer: the model that made it."""

    model: ModelRef


@dataclass(frozen=True)
class Encoded(Result):
    mean: np.ndarray  # (B, latent_dim)
    log_var: np.ndarray
    frames: list[dict[str, Any]] | None  # each curve's frame and pose (frame "auto"); pass them to decode
    closeness: Closeness | None = None  # how close each curve's reading decodes to it, where the server says


@dataclass(frozen=True)
class Curves(Result):
    """Curves an endpoint returned: `curves`, a list of (n_i, 2) arrays (empty with output "bspline")."""

    curves: list[np.ndarray]
    splines: list[dict[str, Any]] | None = None  # with output "bspline" or "both"
    metrics: list[dict[str, Any]] | None = None  # with metrics=True

    def __post_init__(self) -> None:
        # one type whatever was given (nested lists, a (B, n, 2) array): a list of (n_i, 2) arrays
        object.__setattr__(self, "curves", curve_list(self.curves))

    def stacked(self) -> np.ndarray:
        """The curves as one (B, n, 2) array; ValueError where their lengths differ (ask for n_points)."""
        return stacked(self.curves)

    @property
    def curve(self) -> np.ndarray:
        """The curve of a one-curve answer (n, 2); ValueError where the answer holds more or none."""
        return only(self.curves, "curve", "curves")


@dataclass(frozen=True)
class Reconstructed(Curves):
    mse: np.ndarray = field(default_factory=lambda: np.zeros(0))  # (B,) paper eq. 4 at the input's own points
    closeness: Closeness | None = None  # (B,) each reconstruction at its input's points, ÷ the input's diagonal
    repaired: np.ndarray | None = None  # (B,) bool: untangled where it crossed itself and its input did not


@dataclass(frozen=True)
class Interpolated(Curves):
    weights: np.ndarray = field(default_factory=lambda: np.zeros((0, 0)))
    frames: list[dict[str, Any]] | None = None
    valid: np.ndarray | None = None  # (rows,) bool: each returned curve free of self-crossings
    repaired: np.ndarray | None = None  # (rows,) bool: refitted near a crossing
    # (inputs,) each input's own reconstruction in the set's reading (the sweep's end) vs the input; empty for a
    # model that decodes only the mixes
    ends: Closeness | None = None


@dataclass(frozen=True)
class Sampled(Curves):
    latents: np.ndarray = field(default_factory=lambda: np.zeros((0, 0)))
    seed: int = 0
    prior: str = ""
    rejected: int = 0
    invalid: int = 0


@dataclass(frozen=True)
class Augmented(Curves):
    """Items offset … offset + len(curves) - 1 of a seeded augmentation sequence; sources and weights where the
    answer carried them (JSON pages do, .npy chunks carry the curves alone)."""

    sources: np.ndarray | None = None  # (m, k) indices into the seed curves, anchor first
    weights: np.ndarray | None = None  # (m, k)
    frames: list[dict[str, Any]] | None = None
    seed: int = 0
    offset: int = 0
    redrawn: int | None = None  # mixes that crossed themselves and were drawn again (JSON pages)
    invalid: int | None = None  # curves still crossing themselves after 10 draws each (JSON pages; normally 0)
