"""curve_vae.evaluation.prior_report: the yardstick (the training curves scored in the samples' place), curves
resampled by arc length, and the report's table."""

import numpy as np

from curve_vae.evaluation.prior_report import format_report, real_yardstick, resampled


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


def test_curves_are_resampled_evenly_by_arc_length():
    """A polyline 0 → 3 → 3 + 1j (length 4) at 5 points: one every 1 of arc length, corner included."""
    (curve,) = resampled([np.array([[0.0, 0.0], [3.0, 0.0], [3.0, 1.0]])], 5)
    np.testing.assert_allclose(curve, [[0, 0], [1, 0], [2, 0], [3, 0], [3, 1]], atol=1e-12)


def test_the_report_is_a_table_of_each_metric_with_its_interval_and_yardstick():
    report = {
        "prior": "learned",
        "seeds": [0, 1],
        "samples_per_seed": 50,
        "points": 32,
        "held_out": 20,
        "train": 80,
        "held_out_nn_to_train": 0.123456,
        "real": {"mmd_gaussian": 0.001},
        "metrics": {
            "mmd_gaussian": {"mean": 0.0125, "pm": 0.004, "runs": [0.01, 0.015]},
            "valid": {"mean": 1.0, "pm": 0.0, "runs": [1.0, 1.0]},
        },
    }
    lines = format_report(report).splitlines()
    assert lines[0] == (
        "prior learned: 50 samples × 2 seeds against 20 held-out curves (80 training curves), 32 points by arc length; "
        "held-out curves' median distance to the training ones: 0.1235"
    )
    assert lines[2].split() == ["mmd_gaussian", "0.0125", "±", "0.004", "0.001"]
    assert lines[3].split() == ["valid", "1", "±", "0"]  # no yardstick: the real data has no share of valid samples
    assert lines[-1] == "  (real: the training curves in the samples' place)" and len(lines) == 5
