"""The spacing guesser: from a curve's shape alone, the parameter each of its points would have on one of
the paper's splines — where geometry.natural's fit starts for reading pose "learned" (trained by training/spacer.py
on the paper's curves, whose parameters are known, and run as the ONNX graph it exports: the service has no torch).

    caller's curve (n, 2) --by arc length--> (GRID, 2) --turning, its size, position--> (3, GRID)
        --dilated convolutions--> a softmax over the GRID - 1 steps, summed --> parameters (GRID,) in [0, 1]
        --at the caller's points' arc-length fractions--> its guess (n,)

The shape is read through its turning angles at even steps of its length, so the guess does not change when the
curve is moved, turned or scaled, and the way round it turns overall, so that a mirror image is guessed alike; the
network is trained on mirrored and reversed curves alike. Its parameters rise from 0 to 1 by construction (a
softmax's cumulative sum).
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np

from curve_vae.geometry.batch import arc_fractions_of, arc_grids
from curve_vae.inference.model.graphs import ModelGraphs
from curve_vae.inference.model.sessions import SessionConfig

SPACER_KIND = "dilated-conv1d-cumsoftmax-v1"
#: Points a curve is read at, evenly spaced along its length.
GRID = 128
#: Turning angles (radians between neighbouring steps of the grid) are scaled by this: ~1 on a gentle bend.
TURN_SCALE = GRID / 20.0


def on_grid(curves: Sequence[np.ndarray]) -> np.ndarray:
    """(k, GRID, 2): each polyline (n, 2) at GRID points evenly spaced along its length."""
    return arc_grids(curves, GRID)


def spacer_inputs(grid: np.ndarray) -> np.ndarray:
    """(k, GRID, 2) points evenly spaced by arc length -> (k, 3, GRID) float32: the signed turning at each point
    (0 at the two ends) scaled by TURN_SCALE, its size, and the point's place from -1 to 1."""
    step = np.diff(np.asarray(grid, np.float64), axis=1)
    heading = np.arctan2(step[..., 1], step[..., 0])
    turn = np.angle(np.exp(1j * np.diff(heading, axis=1)))  # wrapped to (-π, π]
    turn = np.pad(turn, ((0, 0), (1, 1))) * TURN_SCALE
    place = np.broadcast_to(np.linspace(-1.0, 1.0, grid.shape[1]), turn.shape)
    return np.stack([turn, np.abs(turn), place], axis=1).astype(np.float32)


class Spacer:
    """The guesser's graph (spacer.onnx, exported from training/spacer.py's SpacerNet) and the guesses it gives."""

    def __init__(self, graphs: ModelGraphs) -> None:
        self.graphs = graphs  # runs "spacer"

    @classmethod
    def load(cls, path: str | Path, graphs: ModelGraphs, *, sessions: SessionConfig) -> Spacer:
        """The guesser at `path`, opened beside `graphs` (ModelGraphs.add_part: its input (batch, 3, GRID))."""
        graphs.add_part("spacer", path, shape=(3, GRID), sessions=sessions)
        return cls(graphs)

    def grid_params(self, inputs: np.ndarray) -> np.ndarray:
        """(k, 3, GRID) spacer_inputs -> (k, GRID) parameters from 0 to 1 at the grid's points (the graph's rising
        cumulative sum, made to end at 1 exactly)."""
        u = self.graphs.run_part("spacer", inputs).astype(np.float64)
        return u / u[:, -1:]

    def guesses(self, curves: Sequence[np.ndarray]) -> list[np.ndarray]:
        """Each polyline's (n, 2) guessed parameters at its own points (n,): 0 and 1 at its ends, never falling."""
        if not curves:
            return []
        # the parameters of a mirror image are the curve's own: each curve is read the way round it turns
        # counter-clockwise, so that a curve and its mirror image give the network the same numbers to the last bit
        grid = self.grid_params(spacer_inputs(arc_grids(curves, GRID, upright=True)))
        # each point's parameter, linearly between the grid's (which are evenly spaced in arc length)
        out = []
        for f, u in zip(arc_fractions_of(curves), grid):
            x = f * (GRID - 1)
            j = np.minimum(x.astype(np.int64), GRID - 2)
            out.append(u[j] + (u[j + 1] - u[j]) * (x - j))
        return out
