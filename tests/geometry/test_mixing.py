"""geometry.mixing: the affine weights of /interpolate (paper eqs. 9 and 10) — every row on the simplex, the grid
listed in order, its size without building it, and what too few curves or steps say."""

from itertools import product
from math import comb

import numpy as np
import pytest

from curve_vae.geometry import simplex_grid, simplex_grid_size


def test_three_curves_make_the_barycentric_grid_of_eq_10():
    want = [[1, 0, 0], [0.5, 0.5, 0], [0.5, 0, 0.5], [0, 1, 0], [0, 0.5, 0.5], [0, 0, 1]]
    np.testing.assert_allclose(simplex_grid(3, 3), want)


@pytest.mark.parametrize("n_curves, steps", [(2, 2), (2, 9), (3, 4), (4, 5), (5, 3)])
def test_the_grid_is_every_point_of_the_simplex_lattice_once(n_curves, steps):
    grid = simplex_grid(n_curves, steps)
    # the lattice enumerated independently: every tuple of 0 … steps-1 that sums to steps-1
    lattice = {t for t in product(range(steps), repeat=n_curves) if sum(t) == steps - 1}
    assert {tuple(int(v) for v in np.rint(row * (steps - 1))) for row in grid} == lattice
    assert len(grid) == len(lattice) == simplex_grid_size(n_curves, steps)
    np.testing.assert_allclose(grid.sum(axis=1), 1.0, atol=1e-15)
    assert (grid >= 0).all()
    np.testing.assert_array_equal(grid[0], np.eye(n_curves)[0])  # all weight on the first curve first
    np.testing.assert_array_equal(grid[-1], np.eye(n_curves)[-1])  # and on the last one last


def test_the_size_is_counted_without_building_the_grid():
    # 10 curves at 50 steps would be 1.3e10 rows: the count alone is what a request limit needs
    assert simplex_grid_size(10, 50) == comb(58, 9)


@pytest.mark.parametrize("n_curves, steps", [(1, 5), (3, 1), (0, 0)], ids=["one curve", "one step", "nothing"])
def test_too_few_curves_or_steps_are_refused_naming_both(n_curves, steps):
    with pytest.raises(ValueError, match=f"need ≥ 2 curves and ≥ 2 steps, got {n_curves} and {steps}"):
        simplex_grid(n_curves, steps)


def test_pair_steps_sweep_from_first_to_second_curve():
    np.testing.assert_allclose(simplex_grid(2, 5), [[1, 0], [0.75, 0.25], [0.5, 0.5], [0.25, 0.75], [0, 1]])


def test_triplet_grid_size():
    assert len(simplex_grid(3, 5)) == 15  # steps·(steps+1)/2
