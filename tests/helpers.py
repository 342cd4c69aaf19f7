"""What several test modules share that is not a fixture: the repository's paths and curves of the paper's kind."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from curve_vae.geometry import random_control_points, sample_bspline

ROOT = Path(__file__).resolve().parents[1]
SHIPPED = ROOT / "models"
FIXTURES = ROOT / "tests" / "fixtures"


def bspline_curves(count: int, n_points: int = 161, *, seed: int = 0) -> np.ndarray:
    """(count, n_points, 2) curves of the paper's kind, in the 128×128 plane."""
    return sample_bspline(random_control_points(np.random.default_rng(seed), count), n_points)
