"""What the client's calls return: numpy arrays by name, and the model that made them (`ModelRef`), so a saved batch
says what made it."""

from __future__ import annotations

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


def curves_of(data: list[Any]) -> np.ndarray | list[np.ndarray]:
    """Curves as one (B, n, 2) array where they share a length, else a list of (n_i, 2) arrays."""
    arrays = [np.asarray(c, np.float64).reshape(-1, 2) for c in data]
    if arrays and all(len(a) == len(arrays[0]) for a in arrays):
        return np.stack(arrays)
    return arrays if arrays else np.zeros((0, 0, 2))


@dataclass(frozen=True)
class Result:
    """Every answer: the model that made it."""

    model: ModelRef


@dataclass(frozen=True)
class Encoded(Result):
    mean: np.ndarray  # (B, latent_dim)
    log_var: np.ndarray
    frames: list[dict[str, Any]] | None  # each curve's frame and pose (frame "auto"); pass them to decode


@dataclass(frozen=True)
class Curves(Result):
    curves: np.ndarray | list[np.ndarray]  # (B, n, 2), or a list where lengths differ
    splines: list[dict[str, Any]] | None = None  # with output "bspline" or "both"
    metrics: list[dict[str, Any]] | None = None  # with metrics=True


@dataclass(frozen=True)
class Reconstructed(Curves):
    mse: np.ndarray = field(default_factory=lambda: np.zeros(0))  # (B,) paper eq. 4 at the input's own points


@dataclass(frozen=True)
class Interpolated(Curves):
    weights: np.ndarray = field(default_factory=lambda: np.zeros((0, 0)))
    frames: list[dict[str, Any]] | None = None


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
