"""training/config.py: the model's and the training's configurations check their values when made, and say which
model configurations share their trainable weights."""

import pytest

from curve_vae.errors import InvalidInput
from curve_vae.training.config import ModelConfig, TrainConfig


@pytest.mark.parametrize(
    "given,variant",
    [
        pytest.param("cnn6", "inception", id="cnn6-is-the-inception-network"),
        pytest.param("CNN3", "cnn3", id="case-folded"),
        pytest.param("Inception", "inception", id="inception-case-folded"),
    ],
)
def test_variant_names_are_folded_to_their_one_spelling(given, variant):
    assert ModelConfig(variant=given).variant == variant
    assert ModelConfig(variant=given) == ModelConfig(variant=variant)  # the same model, the same config


@pytest.mark.parametrize(
    "fields,says",
    [
        pytest.param({"latent_dim": 0}, "latent_dim must be ≥ 1, got 0", id="no-latent"),
        pytest.param({"spline_ctrl": 3}, "spline_ctrl must be 0 (off) or 4 … 161, got 3", id="head-too-small"),
        pytest.param({"spline_ctrl": 162}, "spline_ctrl must be 0 (off) or 4 … 161, got 162", id="head-too-large"),
    ],
)
def test_a_model_config_out_of_range_is_refused_by_name(fields, says):
    with pytest.raises(InvalidInput) as e:
        ModelConfig(**fields)
    assert says in str(e.value)


def test_unknown_variant_is_rejected():
    with pytest.raises(ValueError, match="unknown variant"):
        ModelConfig(variant="resnet")


@pytest.mark.parametrize("n_ctrl", [4, 161], ids=["fewest", "one-per-point"])
def test_the_heads_bounds_are_allowed(n_ctrl):
    assert ModelConfig(spline_ctrl=n_ctrl).spline_ctrl == n_ctrl


def test_learned_parameters_need_the_spline_head():
    with pytest.raises(ValueError, match="spline_params needs the B-spline head"):
        ModelConfig(spline_params=True)
    assert not ModelConfig(spline_ctrl=31).same_weights(ModelConfig(spline_ctrl=31, spline_params=True))
    assert ModelConfig(spline_ctrl=31, spline_params=True).same_weights(ModelConfig(spline_ctrl=10, spline_params=True))


@pytest.mark.parametrize(
    "a,b,same",
    [
        pytest.param(ModelConfig(), ModelConfig(spline_ctrl=31), True, id="a-head-has-no-weights"),
        pytest.param(ModelConfig(), ModelConfig(latent_dim=8), False, id="latent-size"),
        pytest.param(ModelConfig(), ModelConfig(variant="cnn1"), False, id="variant"),
        pytest.param(ModelConfig(scale=32.0), ModelConfig(), False, id="normalisation"),
    ],
)
def test_same_weights_ignores_the_head_alone(a, b, same):
    assert a.same_weights(b) is same and b.same_weights(a) is same


def test_only_params_and_only_encoder_exclude_each_other():
    with pytest.raises(ValueError, match="exclude each other"):
        TrainConfig(only_params=True, only_encoder=True)


@pytest.mark.parametrize(
    "fields,says",
    [
        pytest.param({"schedule": "linear"}, "schedule must be one of onecycle, cosine, constant, plateau", id="sched"),
        pytest.param({"schedule": "plateau", "time_budget": 60.0}, "a time budget needs a onecycle", id="budget"),
        pytest.param({"snapshots": -1}, "snapshots must be ≥ 0, got -1", id="snapshots"),
        pytest.param({"match": "nearest"}, "match must be one of index, closest, twin, mixed", id="match"),
        pytest.param({"epochs": 0}, "epochs and batch_size must be ≥ 1 and lr > 0", id="no-epochs"),
        pytest.param({"batch_size": 0}, "epochs and batch_size must be ≥ 1 and lr > 0", id="no-batch"),
        pytest.param({"lr": 0.0}, "epochs and batch_size must be ≥ 1 and lr > 0", id="no-lr"),
    ],
)
def test_a_training_config_out_of_range_is_refused_by_name(fields, says):
    with pytest.raises(InvalidInput) as e:
        TrainConfig(**fields)
    assert says in str(e.value)


def test_a_time_budget_goes_with_every_schedule_but_plateau():
    for schedule in ("onecycle", "cosine", "constant"):
        assert TrainConfig(schedule=schedule, time_budget=60.0).time_budget == 60.0
    assert TrainConfig(schedule="plateau").schedule == "plateau"  # plateau alone, without a budget, is fine
