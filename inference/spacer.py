"""The spacing guesser in numpy: from a curve's shape alone, the parameter each of its points would have on one of
the paper's splines — where geometry.natural's fit starts for reading pose "learned" (trained by training/spacer.py
on the paper's curves, whose parameters are known; the service has no torch).

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

from curve_vae.errors import InvalidInput
from curve_vae.geometry.batch import arc_fractions_of, arc_grids
from curve_vae.inference.weights import read_weights

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
    """The guesser's weights (spacer.npz) and its forward pass."""

    def __init__(self, weights: dict[str, np.ndarray]) -> None:
        try:
            self.dilations = [int(d) for d in weights["dilations"]]
            self.mix_after = int(weights["mix_after"])
            self.inp = _pair(weights, "inp")
            self.blocks = [
                (_pair(weights, f"block{i}_a"), _pair(weights, f"block{i}_b")) for i in range(len(self.dilations))
            ]
            self.mix = _pair(weights, "mix")
            self.out = _pair(weights, "out")
        except KeyError as e:
            raise InvalidInput(f"not a spacing guesser: no {e.args[0]} weights") from None

    @classmethod
    def load(cls, path: str | Path) -> Spacer:
        return cls(read_weights(path, SPACER_KIND, "a spacing guesser"))

    def grid_params(self, inputs: np.ndarray) -> np.ndarray:
        """(k, 3, GRID) spacer_inputs -> (k, GRID) parameters from 0 to 1 at the grid's points."""
        h = _conv(inputs.transpose(0, 2, 1), *self.inp, dilation=1)  # channels last: each tap one matrix product
        for i, ((wa, ba), (wb, bb)) in enumerate(self.blocks):
            inner = _conv(np.maximum(h, 0.0), wa, ba, dilation=self.dilations[i])
            h = h + _conv(np.maximum(inner, 0.0), wb, bb, dilation=1)
            if i == self.mix_after:
                w, b = self.mix
                h = h + (h.mean(1) @ w.T + b)[:, None, :]
        w, b = self.out  # (1, c, 2): one logit per step between neighbouring points
        h = np.maximum(h, 0.0)
        logit = h[:, :-1] @ w[0, :, 0] + h[:, 1:] @ w[0, :, 1] + b[0]
        logit = logit - logit.max(axis=1, keepdims=True)
        step = np.exp(logit.astype(np.float64))
        u = np.concatenate([np.zeros((len(step), 1)), np.cumsum(step, axis=1)], axis=1)
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


def _pair(weights: dict[str, np.ndarray], name: str) -> tuple[np.ndarray, np.ndarray]:
    return weights[f"{name}_w"].astype(np.float32), weights[f"{name}_b"].astype(np.float32)


def _conv(h: np.ndarray, w: np.ndarray, b: np.ndarray, *, dilation: int) -> np.ndarray:
    """A 1-D convolution of (k, n, c) with weights (o, c, taps), zero-padded to keep n: the middle tap's (k, n, c) @
    (c, o) product, then each other tap's product added into the rows it reaches (the zero padding contributes
    nothing, so it is never built: 32 curves' guesses 27.5 -> 18 ms against a padded copy per convolution)."""
    n = h.shape[1]
    mid = w.shape[2] // 2
    out = h @ w[:, :, mid].T + b
    for t in range(w.shape[2]):
        shift = (t - mid) * dilation  # out[j] += h[j + shift] @ w[:, :, t].T where j + shift is a row of h
        if t == mid or abs(shift) >= n:
            continue
        if shift > 0:
            out[:, : n - shift] += h[:, shift:] @ w[:, :, t].T
        else:
            out[:, -shift:] += h[:, : n + shift] @ w[:, :, t].T
    return out
