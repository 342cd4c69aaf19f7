"""inference.generation.augmenting: who may be mixed with whom (`neighbour_pools`: nearest latent means, or every
other curve)
and the seeded rule that draws item i of an augmentation sequence (`AugmentPlan.draw`) — the same item whatever the
page it is drawn in, its partners distinct and from its anchor's pool, its weights on the simplex."""

import re

import numpy as np
import pytest

from curve_vae.inference.errors import InputError
from curve_vae.inference.generation.augmenting import AugmentPlan, neighbour_pools
from curve_vae.inference.prepared import Prepared

#: latent means on a line (1-D), at distances a reader can check by eye
LINE = np.array([[0.0], [1.0], [3.0], [7.0], [15.0]])


def test_pools_are_each_curves_nearest_means_in_ascending_order():
    # 0: 1 at 1, 2 at 3 | 1: 0 at 1, 2 at 2 | 2: 1 at 2, 0 at 3 | 3: 2 at 4, 1 at 6 | 4: 3 at 8, 2 at 12
    np.testing.assert_array_equal(neighbour_pools(LINE, "pair", 2), [[1, 2], [0, 2], [0, 1], [1, 2], [2, 3]])
    np.testing.assert_array_equal(neighbour_pools(LINE, "triplet", 2), neighbour_pools(LINE, "pair", 2))


def test_without_neighbours_every_other_curve_is_in_the_pool():
    np.testing.assert_array_equal(
        neighbour_pools(LINE, "pair", None), [[j for j in range(5) if j != i] for i in range(5)]
    )


def test_pools_measure_distance_in_every_latent_dimension():
    means = np.array([[0.0, 0.0], [3.0, 4.0], [0.0, 6.0], [5.9, 0.0]])  # from 0: 5, 6, 5.9
    assert neighbour_pools(means, "pair", 1)[0].tolist() == [1]
    assert neighbour_pools(means, "pair", 2)[0].tolist() == [1, 3]


def test_equally_near_curves_are_taken_in_index_order():
    means = np.array([[0.0], [-1.0], [1.0], [-1.0]])
    assert neighbour_pools(means, "pair", 1)[0].tolist() == [1]  # 1, 2 and 3 all at distance 1: the first


BAD_POOLS = {
    "too few curves for a triplet": (
        LINE[:2],
        "triplet",
        None,
        ("curves",),
        "mode triplet needs at least 3 curves, got 2",
    ),
    "too few neighbours for a triplet": (
        LINE,
        "triplet",
        1,
        ("neighbours",),
        "mixes each curve with 2 others: at least 2, got 1",
    ),
    "more neighbours than curves": (LINE, "pair", 5, ("neighbours",), "at most 4 (each curve has 4 others), got 5"),
}


@pytest.mark.parametrize("means, mode, neighbours, loc, message", BAD_POOLS.values(), ids=BAD_POOLS.keys())
def test_pools_that_cannot_be_met_are_refused_naming_the_field(means, mode, neighbours, loc, message):
    with pytest.raises(InputError, match=re.escape(message)) as caught:
        neighbour_pools(means, mode, neighbours)
    assert caught.value.loc == loc


def _plan(k: int, seed: int = 7, neighbours: int | None = 2) -> AugmentPlan:
    mode = {2: "pair", 3: "triplet"}[k]
    return AugmentPlan(Prepared([], []), LINE, k, seed, neighbour_pools(LINE, mode, neighbours))


@pytest.mark.parametrize("k", [2, 3], ids=["pair", "triplet"])
def test_an_item_is_the_same_whatever_page_it_is_drawn_in(k):
    plan = _plan(k)
    sources, weights = plan.draw(0, 12)
    pages = [plan.draw(a, b) for a, b in ((0, 5), (5, 6), (6, 12))]
    np.testing.assert_array_equal(np.concatenate([s for s, _ in pages]), sources)
    np.testing.assert_array_equal(np.concatenate([w for _, w in pages]), weights)
    later_s, later_w = plan.draw(9, 11)  # drawn alone, in any order
    np.testing.assert_array_equal(later_s, sources[9:11])
    np.testing.assert_array_equal(later_w, weights[9:11])


@pytest.mark.parametrize("k", [2, 3], ids=["pair", "triplet"])
def test_each_item_mixes_its_anchor_with_distinct_partners_from_its_pool(k):
    plan = _plan(k)
    sources, weights = plan.draw(0, 200)
    assert sources.shape == weights.shape == (200, k) and sources.dtype == np.int64
    for row in sources:
        anchor, partners = row[0], row[1:]
        assert set(partners) <= set(plan.pools[anchor]) and anchor not in partners
        assert len(set(partners)) == k - 1
    assert set(sources[:, 0]) == set(range(len(LINE)))  # every curve is an anchor somewhere in 200 draws
    assert (weights >= 0).all()
    np.testing.assert_allclose(weights.sum(axis=1), 1.0)


def test_the_seed_decides_the_sequence():
    a, b, again = _plan(2, seed=1), _plan(2, seed=2), _plan(2, seed=1)
    assert not np.array_equal(a.draw(0, 20)[1], b.draw(0, 20)[1])
    np.testing.assert_array_equal(a.draw(0, 20)[1], again.draw(0, 20)[1])


def test_an_empty_page_is_empty():
    sources, weights = _plan(3).draw(4, 4)
    assert sources.shape == weights.shape == (0, 3)
