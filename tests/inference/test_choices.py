"""inference.choices: the choices every front end offers, spelled once — an option's description made of its values
with the default marked, the Literal's values as argparse choices, and the choices that are derived from others
kept in step with them."""

from typing import get_args

import pytest

from curve_vae.inference.choices import (
    MAX_REFINE_STEPS,
    POSE,
    REFINE,
    SOURCES_PER_MODE,
    SPACING,
    AugmentMode,
    ModelPose,
    ModelSpacing,
    Option,
    Placement,
    Pose,
    Spacing,
    SplinePlacement,
    choices,
)

DEMO = Option("one line", {"a": "first.", "b": "second."}, before="Opening.", after="Closing.")


def test_a_description_lists_the_values_in_order_and_marks_the_default():
    assert DEMO.description("b") == 'Opening. "a": first. "b" (default): second. Closing.'
    assert DEMO.description("neither") == 'Opening. "a": first. "b": second. Closing.'


def test_a_description_without_an_opening_closing_or_values_has_no_stray_spaces():
    assert Option("x", {"only": "it."}).description("only") == '"only" (default): it.'
    assert REFINE.description(0) == REFINE.before  # an integer option: its text alone


def test_choices_are_a_literals_values_in_order():
    assert choices(SplinePlacement) == ("closest", "index")
    assert choices(Placement) == ("model", "closest", "index")  # "model", then every placement a manifest names


@pytest.mark.parametrize(
    "derived, full",
    [(ModelPose, Pose), (ModelSpacing, Spacing)],
    ids=["pose", "spacing"],
)
def test_a_models_own_reading_is_any_value_but_auto(derived, full):
    assert choices(derived) == tuple(v for v in choices(full) if v != "auto")


def test_each_augment_mode_says_how_many_curves_it_mixes():
    assert tuple(SOURCES_PER_MODE) == get_args(AugmentMode)
    assert SOURCES_PER_MODE == {"pair": 2, "triplet": 3}  # paper eqs. 9 and 10


def test_refine_is_bounded_by_the_most_steps_a_request_may_ask():
    assert (REFINE.ge, REFINE.le) == (0, MAX_REFINE_STEPS) and REFINE.values == {}


@pytest.mark.parametrize("option", [POSE, SPACING], ids=["pose", "spacing"])
def test_the_search_is_described_with_its_cost(option):
    # the documentation users read when they pick the search must say it multiplies the inference
    assert "closest to the input kept" in option.values["search"] and "×" in option.values["search"]
