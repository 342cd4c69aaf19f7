"""The page's sweep of the README's pair in a real browser: the in-betweens turn from one chord to the other."""

from __future__ import annotations

import numpy as np
import pytest

from tests.e2e.test_page import H, browser, draw, open_page, server, state  # noqa: F401 (fixtures)

pytestmark = pytest.mark.integration

#: The README's pair (docs/API.md), scaled onto the board: both start at one point and head right, at 0° and 47°.
PAIR = [
    [[0, 0], [1, 2], [2.5, 3.2], [4, 3.5], [5.5, 3], [7, 1.5], [8, 0]],
    [[0, 0], [1.5, 0.5], [3, 2], [4, 4], [5, 6.5], [6.5, 8], [8, 8.5]],
]


def _on_board(curve: list[list[float]]) -> list[tuple[float, float]]:
    """Board units (1000 × 700, y down) of a curve in API units (y up), densified as a hand would draw it."""
    c = np.asarray(curve, float)
    t = np.linspace(0, len(c) - 1, 40)
    dense = np.stack([np.interp(t, np.arange(len(c)), c[:, k]) for k in (0, 1)], axis=1)
    return [(300 + 50 * x, H - (150 + 50 * y)) for x, y in dense]


def test_the_readme_pair_sweeps_round_monotonically(browser, server):  # noqa: F811 (the fixtures above)
    page, errors = open_page(browser, server.url + "/")
    for curve in PAIR:
        draw(page, _on_board(curve))
    page.wait_for_function("window.curveVae.strip && window.curveVae.strip.length === 5")
    strip = np.asarray(state(page)["strip"], float)  # the five in-betweens the page shows, API units
    chords = np.degrees(np.arctan2(*(strip[:, -1] - strip[:, 0]).T[::-1]))
    assert np.all(np.diff(chords) > 0), chords
    assert abs(chords[0]) < 5 and abs(chords[-1] - 47) < 5, chords
    assert errors == []
