"""The evaluation's yardstick: the training curves scored in the samples' place."""

import numpy as np

from curve_vae.evaluation.prior_report import real_yardstick, resampled


def _waves(count: int, shift: float = 0.0) -> np.ndarray:
    t = np.linspace(0, 1, 40)
    rng = np.random.default_rng(3)
    return resampled([np.stack([t, a * np.sin(np.pi * t) + shift], 1) for a in rng.uniform(0.2, 1.0, count)], 32)


def test_data_against_itself_scores_as_a_perfect_generator():
    x = _waves(60)
    real = real_yardstick(x, x)
    assert abs(real["mmd_ideallab"]) < 1e-12 and abs(real["mmd_gaussian"]) < 1e-12
    assert real["precision"] == real["recall"] == real["coverage"] == 1.0 and real["rvod"] == 1.0


def test_a_shifted_training_set_is_told_apart():
    held, train = _waves(60), _waves(60, shift=5.0)
    real = real_yardstick(held, train)
    assert real["mmd_gaussian"] > 0.5 and real["precision"] == 0.0 and real["recall"] == 0.0


def test_at_most_count_training_curves_stand_in():
    held, train = _waves(30), _waves(90)
    assert real_yardstick(held, train, count=30) == real_yardstick(held, train[:30])
