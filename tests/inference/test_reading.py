"""inference.reading: one value for how curves are read, "auto" made the model's own; the one definition the
request schema, the command line's flags and the checks are made of."""

import argparse

import pytest

from curve_vae.errors import InvalidInput
from curve_vae.inference.choices import MAX_REFINE_STEPS
from curve_vae.inference.model.manifest import ReadingSpec
from curve_vae.inference.reading import Reading, reading_options


def test_auto_is_the_models_reading_and_explicit_values_stay():
    canonical = ReadingSpec(pose="canonical", spacing="parameter")
    assert Reading().resolved(canonical) == Reading(pose="canonical", spacing="parameter")
    assert Reading().resolved(ReadingSpec()) == Reading(pose="search", spacing="search")
    assert Reading(pose="as_is", spacing="natural").resolved(canonical) == Reading(pose="as_is", spacing="natural")
    assert Reading(frame="model").resolved(canonical).pose == "as_is"  # points in the plane keep their pose
    assert Reading(pose="search").resolved(canonical).searches and not Reading().resolved(canonical).searches
    assert Reading(refine=3).key != Reading().key


# ---- one definition: the request schema, the command line and the checks are all made of Reading's fields


@pytest.mark.parametrize("option", reading_options(), ids=lambda o: o.name)
def test_every_value_of_an_option_is_documented_and_nothing_else(option):
    """Adding a value to a Literal without its line in the Option (or the reverse) fails here."""
    if option.values:
        assert tuple(option.doc.values) == option.values
        for value in option.values:
            assert f'"{value}"' in option.doc.description(option.default)
    else:
        assert option.kind is int and option.doc.ge is not None and option.doc.le is not None


@pytest.mark.parametrize(
    ("fields", "named"),
    [
        pytest.param({"pose": "sideways"}, "pose", id="unknown-pose"),
        pytest.param({"spacing": "even"}, "spacing", id="unknown-spacing"),
        pytest.param({"frame": "plane"}, "frame", id="unknown-frame"),
        pytest.param({"refine": MAX_REFINE_STEPS + 1}, "refine", id="too-many-steps"),
        pytest.param({"refine": -1}, "refine", id="negative-steps"),
        pytest.param({"refine": True}, "refine", id="bool-steps"),
        pytest.param({"refine": 2.0}, "refine", id="float-steps"),
    ],
)
def test_a_reading_outside_its_options_is_refused_naming_the_field(fields, named):
    with pytest.raises(InvalidInput) as caught:
        Reading(**fields)
    assert caught.value.loc == (named,)
    assert named in str(caught.value)


def test_the_request_schema_is_made_of_the_options():
    from curve_vae.service.schemas import ReadingIn, ReconstructRequest

    names = [o.name for o in reading_options()]
    assert list(ReadingIn.model_fields) == names
    props = ReconstructRequest.model_json_schema()["properties"]
    for o in reading_options():
        assert props[o.name]["default"] == o.default
        assert props[o.name]["description"] == o.doc.description(o.default)
        if o.values:
            assert tuple(props[o.name]["enum"]) == o.values
        else:
            assert (props[o.name]["minimum"], props[o.name]["maximum"]) == (o.doc.ge, o.doc.le)
    body = ReconstructRequest(curves=[[[0, 0], [1, 1], [2, 0], [3, 1]]], pose="learned", refine=2)
    assert body.reading() == Reading(pose="learned", refine=2)


@pytest.mark.parametrize("command", ["reconstruct", "encode", "augment"])
def test_the_commands_flags_are_made_of_the_options(command):
    from curve_vae.cli import build_parser

    sub = next(a for a in build_parser()._actions if isinstance(a, argparse._SubParsersAction))
    flags = {a.dest: a for a in sub.choices[command]._actions}
    for o in reading_options():
        assert flags[o.name].default == o.default
        assert tuple(flags[o.name].choices or ()) == o.values
        assert o.doc.summary in flags[o.name].help


def test_a_refine_beyond_the_bound_stops_the_command_before_it_reads(tmp_path, capsys):
    from curve_vae.cli import main

    missing = tmp_path / "not-there.json"  # never opened: the reading is checked first
    assert main(["reconstruct", str(missing), "--refine", str(MAX_REFINE_STEPS + 1)]) == 2
    err = capsys.readouterr().err
    assert "refine" in err and str(MAX_REFINE_STEPS) in err and "not-there" not in err
