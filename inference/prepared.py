"""A batch of caller curves brought to the model (`Prepared`), and the candidate readings it is chosen from
(`Candidates`: each curve in each pose and spacing the request allows, encoded, decoded and measured; the runtime
keeps each curve's closest)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from curve_vae.geometry import Frame


@dataclass(frozen=True)
class Prepared:
    """A batch of caller curves brought to the model, and what it takes to bring results back."""

    model: np.ndarray  # (B, n_points, 2) float32 in the model plane
    frames: list[Frame | None]  # the caller's frame of each curve; None for frame "model"
    fractions: list[
        np.ndarray | None
    ]  # where each input point sits along the model's points, in [0, 1]; None: same points
    inputs: list[np.ndarray]  # the caller's curves, float64
    # With pose "auto", the curves are already encoded and decoded (that is how the pose is chosen):
    mean: np.ndarray | None = None  # (B, latent_dim)
    log_var: np.ndarray | None = None
    decoded: np.ndarray | None = None  # (B, n_points, 2) model plane
    ctrl: np.ndarray | None = None  # (B, n_ctrl, 2) with a B-spline head
    params: np.ndarray | None = None  # (B, n_points) spline parameter of each model point, if the head learns them
    # With refine, the latents are fitted (inference.fitting) and each input point is matched to its closest point:
    feet: list[np.ndarray] | None = None  # per curve, the spline parameter (model order) of each input point


@dataclass(frozen=True)
class Candidates:
    """Readings of caller curves tried on the model (several per curve, in any order): what
    `CurveRuntime._prepare` chooses from, each measured by how far its reconstruction is from its model-plane points
    (`err`)."""

    owner: list[int]  # the curve each candidate reads
    model: np.ndarray
    frames: list[Frame | None]
    fractions: list[np.ndarray | None]
    mean: np.ndarray
    log_var: np.ndarray
    decoded: np.ndarray
    ctrl: np.ndarray | None
    params: np.ndarray | None
    err: np.ndarray

    def closest(self, inputs: list[np.ndarray]) -> Prepared:
        """Each curve's candidate whose reconstruction came closest."""
        owner = np.asarray(self.owner, int)
        best = [int(np.flatnonzero(owner == i)[self.err[owner == i].argmin()]) for i in range(len(inputs))]
        return Prepared(
            self.model[best],
            [self.frames[b] for b in best],
            [self.fractions[b] for b in best],
            inputs,
            self.mean[best],
            self.log_var[best],
            self.decoded[best],
            None if self.ctrl is None else self.ctrl[best],
            None if self.params is None else self.params[best],
        )
