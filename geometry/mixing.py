"""Interpolation weights (paper eqs. 9 and 10): the affine weights that mix the latent means of 2, 3 or more curves.

Used by the service's /interpolate (a grid of `steps`) and by the evaluation's interpolation report alike.
"""

from __future__ import annotations

import math

import numpy as np

from curve_vae.errors import InvalidInput


def simplex_grid(n_curves: int, steps: int) -> np.ndarray:
    """Evenly spaced affine weights, one column per curve: all (i_1, …, i_n)/(steps-1) summing to 1.

    Two curves give the even sweep of paper eq. 9 from [1, 0] to [0, 1] (steps rows); three
    give the barycentric grid of eq. 10 (steps·(steps+1)/2 rows). First row: all weight on
    the first curve; last row: all on the last.
    """
    if n_curves < 2 or steps < 2:
        raise InvalidInput(f"need ≥ 2 curves and ≥ 2 steps, got {n_curves} and {steps}")

    def compositions(total: int, parts: int) -> list[list[int]]:
        if parts == 1:
            return [[total]]
        return [[i, *rest] for i in range(total, -1, -1) for rest in compositions(total - i, parts - 1)]

    return np.array(compositions(steps - 1, n_curves), dtype=np.float64) / (steps - 1)


def simplex_grid_size(n_curves: int, steps: int) -> int:
    """Rows of `simplex_grid(n_curves, steps)`, without building it."""
    return math.comb(steps - 1 + n_curves - 1, n_curves - 1)
