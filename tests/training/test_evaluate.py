"""The evaluation report's numbers on inputs whose answer is known."""

import numpy as np

from curve_vae.training.evaluate import evaluate_set


def _curves(n: int = 4, points: int = 161) -> np.ndarray:
    t = np.linspace(0, 1, points)
    return np.stack([np.stack([40 * t + k, 20 * np.sin(3 * t) + k], axis=-1) for k in range(n)])


def test_error_at_one_end_is_located_there():
    curves = _curves()
    recon = curves.copy()
    recon[:, 0] += 2.0  # every curve off by (2, 2) px at its first point only
    r = evaluate_set(curves, recon)
    assert np.isclose(r["mse_first_point"], 4.0)
    assert r["mse_last_point"] == 0.0
    assert np.isclose(r["error_share_first_last_10_points"], 1.0)
    assert np.isclose(r["mse"], 4.0 / 161)


def test_error_spread_evenly_gives_the_ends_their_share():
    curves = _curves()
    r = evaluate_set(curves, curves + 0.5)
    assert np.isclose(r["mse_first_point"], 0.25) and np.isclose(r["mse_last_point"], 0.25)
    assert np.isclose(r["error_share_first_last_10_points"], 20 / 161)
