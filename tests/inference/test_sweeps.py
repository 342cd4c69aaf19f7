"""Sweeps between curves read as one set (inference.reader's shared pose): the README's pair turns as its curves
do, and a set moved moves its sweep (a curve mixed with its reversal: tests/inference/test_pose.py)."""

from __future__ import annotations

import numpy as np

from curve_vae.geometry.morph import end_drift, turn_excess

README_PAIR = [
    np.array([[0, 0], [1, 2], [2.5, 3.2], [4, 3.5], [5.5, 3], [7, 1.5], [8, 0]], float),
    np.array([[0, 0], [1.5, 0.5], [3, 2], [4, 4], [5, 6.5], [6.5, 8], [8, 8.5]], float),
]
STEPS = np.array([[1 - t, t] for t in np.linspace(0, 1, 5)])


def test_the_readme_pair_turns_from_one_chord_to_the_other(shipped_runtime):
    sweep = np.stack(shipped_runtime.interpolate(README_PAIR, STEPS).curves)
    chords = np.degrees(np.arctan2(*(sweep[:, -1] - sweep[:, 0]).T[::-1]))
    assert np.all(np.diff(chords) > 0), chords  # 0° -> 47°, every step further round
    assert turn_excess(sweep) <= 10.0
    assert end_drift(sweep) <= 0.1


def test_a_sweep_moves_with_its_pair(shipped_runtime):
    turn = np.array([[0.6, 0.8], [-0.8, 0.6]])
    moved = [c @ turn * 30 + [500, -20] for c in README_PAIR]
    sweep = np.stack(shipped_runtime.interpolate(README_PAIR, STEPS).curves)
    swept = np.stack(shipped_runtime.interpolate(moved, STEPS).curves)
    np.testing.assert_allclose(swept, sweep @ turn * 30 + [500, -20], atol=1e-6 * 30 * 8)
