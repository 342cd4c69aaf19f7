"""geometry.morph: how far a sweep's chords turn past its ends' and its end points stray."""

from __future__ import annotations

import numpy as np
import pytest

from curve_vae.geometry.morph import end_drift, turn_excess


def _segment(angle_deg: float, start=(0.0, 0.0), length: float = 10.0) -> np.ndarray:
    a = np.radians(angle_deg)
    s = np.asarray(start, float)
    return np.stack([s + t * length * np.array([np.cos(a), np.sin(a)]) for t in np.linspace(0, 1, 5)])


@pytest.mark.parametrize(
    "angles,excess",
    [
        pytest.param([0, 10, 20, 30, 47], 0.0, id="monotone"),
        pytest.param([0, -17, -67, 64, 47], 67.0, id="swinging-round"),
        pytest.param([170, 180, -170], 0.0, id="across-the-cut"),
        pytest.param([47, 60, 0], 13.0, id="overshoot"),
    ],
)
def test_turn_excess(angles, excess):
    assert turn_excess(np.stack([_segment(a) for a in angles])) == pytest.approx(excess, abs=1e-9)


def test_pointwise_blending_does_not_drift_and_a_detour_does():
    a, b = _segment(0), _segment(47)
    blend = np.stack([(1 - t) * a + t * b for t in np.linspace(0, 1, 5)])
    assert end_drift(blend) == pytest.approx(0.0, abs=1e-12)
    away = blend.copy()
    away[2] += [0.0, 5.0]
    diagonal = np.hypot(*np.ptp(np.concatenate([a, b]), axis=0))
    # both ends start at the origin: the middle curve's first point is 5 off that (one-point) segment, its last
    # point at most 5 off the other
    assert end_drift(away) == pytest.approx(5.0 / diagonal, rel=1e-12)
