"""The reading ranker: from each candidate reading's model-plane points, the natural log of the relative RMSE the model
would bring it back at (trained by training/ranker.py against the frozen graphs, run as the ONNX graph it exports:
the service has no torch, and onnxruntime releases the GIL while it runs). Reading pose "learned" encodes only the
candidate it ranks first (inference.reader), then looks again (inference.looking).

The network: the points centred on the plane and their steps along the curve (4 channels), three convolutions of
kernel 5 and stride 2 with ReLU, the mean and the maximum over the curve, a hidden layer, one output.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from curve_vae.geometry.frame import MODEL_CENTER
from curve_vae.inference.model.graphs import ModelGraphs
from curve_vae.inference.model.sessions import SessionConfig

RANKER_KIND = "conv1d-3x5s2-meanmax-v1"
#: Readings pose "learned" encodes per curve: the ranker's first. With a look again after it, the first alone reads
#: closer than the closer of the first two read without one, at the same graph passes (docs/RESULTS.md, "Readings").
RANKED_READS = 1
#: Scale of the plane (half its side) and of a step between neighbouring points in the ranker's inputs.
PLANE_HALF = 64.0
STEP_SCALE = 20.0
#: Candidates the ranker scores at once.
SCORE_CHUNK = 128


def ranker_inputs(points: np.ndarray) -> np.ndarray:
    """(k, n, 2) model-plane points -> (k, 4, n) float32: the points about the plane's centre, in half-sides, and
    each point's step from the one before (the first repeats the second's), scaled to about unit size."""
    p = (np.asarray(points, np.float32) - np.float32(MODEL_CENTER[0])) / np.float32(PLANE_HALF)
    step = np.diff(p, axis=1)
    step = np.concatenate([step[:, :1], step], axis=1) * np.float32(STEP_SCALE * (p.shape[1] - 1) / 160)
    return np.ascontiguousarray(np.concatenate([p, step], axis=2).transpose(0, 2, 1))


class Ranker:
    """The ranker's graph (ranker.onnx, exported from training/ranker.py's RankerNet) and the scores it gives."""

    def __init__(self, graphs: ModelGraphs) -> None:
        self.graphs = graphs  # runs "ranker"

    @classmethod
    def load(cls, path: str | Path, graphs: ModelGraphs, *, sessions: SessionConfig) -> Ranker:
        """The ranker at `path`, opened beside `graphs` (ModelGraphs.add_part: its input (batch, 4, n_points))."""
        graphs.add_part("ranker", path, shape=(4, graphs.n_points), sessions=sessions)
        return cls(graphs)

    def scores(self, points: np.ndarray) -> np.ndarray:
        """(k, n, 2) model-plane points -> (k,) predicted natural log of each reading's relative RMSE; SCORE_CHUNK
        candidates at a time (a chunk's activations stay in cache)."""
        if len(points) == 0:
            return np.zeros(0)
        return np.concatenate(
            [
                self.graphs.run_part("ranker", ranker_inputs(points[i : i + SCORE_CHUNK]))
                for i in range(0, len(points), SCORE_CHUNK)
            ]
        ).astype(np.float64)
