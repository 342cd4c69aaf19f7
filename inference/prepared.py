"""A caller's curve as the model read it (`ReadCurve`: its frame, the model-plane points the encoder saw, its latent,
the decoded spline and where the caller's points sit on it), and a batch of them (`Prepared`). The encoding cache
keeps ReadCurves; the runtime fills in what a call needs (the decoding, the placement) and maps results back."""

from __future__ import annotations

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
    pin: np.ndarray | None = None  # (n_ctrl, 2) float64: how `ctrl` was moved onto the input's ends (inference.ends)
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
    ends_kept: bool = True  # answers start and end where their inputs do; so do curves mixed of them (inference.ends)

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
