"""The reading ranker in numpy: from each candidate reading's model-plane points, the natural log of the relative
RMSE the model would bring it back at (trained by training/ranker.py against the frozen graphs; the service has no
torch). Reading pose "learned" encodes only the two candidates it ranks first (inference.reader).

The network: the points centred on the plane and their steps along the curve (4 channels), three convolutions of
kernel 5 and stride 2 with ReLU, the mean and the maximum over the curve, a hidden layer, one output.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from numpy.lib.stride_tricks import as_strided

from curve_vae.errors import InvalidInput
from curve_vae.geometry.frame import MODEL_CENTER
from curve_vae.inference.weights import read_weights

RANKER_KIND = "conv1d-3x5s2-meanmax-v1"
#: Readings pose "learned" encodes per curve: the ranker's first two.
RANKED_READS = 2
#: Scale of the plane (half its side) and of a step between neighbouring points in the ranker's inputs.
PLANE_HALF = 64.0
STEP_SCALE = 20.0
#: Candidates the ranker scores at once (in one process, 2,300 candidates: 270 and 160 ms at once, 115–135 in chunks
#: of 128).
SCORE_CHUNK = 128


def ranker_inputs(points: np.ndarray) -> np.ndarray:
    """(k, n, 2) model-plane points -> (k, 4, n) float32: the points about the plane's centre, in half-sides, and
    each point's step from the one before (the first repeats the second's), scaled to about unit size."""
    p = (np.asarray(points, np.float32) - np.float32(MODEL_CENTER[0])) / np.float32(PLANE_HALF)
    step = np.diff(p, axis=1)
    step = np.concatenate([step[:, :1], step], axis=1) * np.float32(STEP_SCALE * (p.shape[1] - 1) / 160)
    return np.ascontiguousarray(np.concatenate([p, step], axis=2).transpose(0, 2, 1))


class Ranker:
    """The ranker's weights (ranker.npz) and its forward pass."""

    def __init__(self, weights: dict[str, np.ndarray]) -> None:
        self.convs: list[tuple[np.ndarray, np.ndarray, int]] = []  # (taps·in, out) weights, bias, taps
        i = 0
        while f"conv{i}_w" in weights:
            w = weights[f"conv{i}_w"].astype(np.float32)  # (out, in, taps)
            # as (taps·in, out): a window of the input's rows (channels last), flattened, times it is the convolution
            flat = np.ascontiguousarray(w.transpose(2, 1, 0).reshape(-1, len(w)))
            self.convs.append((flat, weights[f"conv{i}_b"].astype(np.float32), w.shape[2]))
            i += 1
        self.dense = []
        i = 0
        while f"dense{i}_w" in weights:
            self.dense.append((weights[f"dense{i}_w"].astype(np.float32), weights[f"dense{i}_b"].astype(np.float32)))
            i += 1
        if not self.convs or len(self.dense) != 2:
            raise InvalidInput("not a reading ranker: expected conv0… and dense0, dense1 weights")

    @classmethod
    def load(cls, path: str | Path) -> Ranker:
        return cls(read_weights(path, RANKER_KIND, "a ranker"))

    def scores(self, points: np.ndarray) -> np.ndarray:
        """(k, n, 2) model-plane points -> (k,) predicted natural log of each reading's relative RMSE; SCORE_CHUNK
        candidates at a time (a chunk's windows stay in cache: all ~2,300 candidates of a 128-curve request at once
        spend more time faulting in fresh pages than multiplying)."""
        if len(points) == 0:
            return np.zeros(0)
        return np.concatenate([self._scores(points[i : i + SCORE_CHUNK]) for i in range(0, len(points), SCORE_CHUNK)])

    def _scores(self, points: np.ndarray) -> np.ndarray:
        h = ranker_inputs(points).transpose(0, 2, 1)  # (k, n, c): each step one matrix product
        for w, b, taps in self.convs:
            k, n, c = h.shape
            pad = taps // 2
            padded = np.zeros((k, n + 2 * pad, c), np.float32)
            padded[:, pad : pad + n] = h
            n_out = (n + 2 * pad - taps) // 2 + 1
            # stride 2: window j is rows 2j … 2j + taps - 1 of the padded input, taps·c floats in a row in memory, so
            # the windows' copy into one matrix is a copy of contiguous runs (a 5-element gather per channel is not)
            s0, s1, s2 = padded.strides
            windows = as_strided(padded, (k, n_out, taps * c), (s0, 2 * s1, s2), writeable=False)
            h = np.maximum(windows.reshape(k * n_out, taps * c) @ w + b, 0.0).reshape(k, n_out, len(b))
        z = np.concatenate([h.mean(1), h.max(1)], axis=1)
        (w0, b0), (w1, b1) = self.dense
        z = np.maximum(z @ w0.T + b0, 0.0)
        return (z @ w1.T + b1)[:, 0].astype(np.float64)
