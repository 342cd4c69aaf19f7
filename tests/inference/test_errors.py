"""inference.errors: how an InputError names the field, curve and point of a request it cannot process (`format_loc`),
and what it carries for the service's 422 answer (loc, msg)."""

import pytest

from curve_vae.inference.errors import InputError, format_loc

LOCS = {
    "a point's coordinate": (("curves", 2, 17, 1), "curves[2][17][1]"),
    "a field": (("refine",), "refine"),
    "a nested field": (("limits", "max_points"), "limits.max_points"),
    "a field of a list item": (("curves", 0, "points"), "curves[0].points"),
    "a list index alone": ((3,), "[3]"),
    "the whole body": ((), "body"),
}


@pytest.mark.parametrize("loc, text", LOCS.values(), ids=LOCS.keys())
def test_format_loc_writes_a_location_as_python_would_index_it(loc, text):
    assert format_loc(loc) == text


def test_an_input_error_leads_with_its_location_and_keeps_both_parts():
    e = InputError(["curves", 4], "all points coincide")
    assert str(e) == "curves[4]: all points coincide"
    # the service answers {"loc": [...], "msg": ...}: a tuple, whatever sequence the raiser passed
    assert e.loc == ("curves", 4) and e.msg == "all points coincide"


def test_an_input_error_is_caught_as_a_value_error_with_its_message():
    with pytest.raises(ValueError, match=r"^body: empty$"):
        raise InputError((), "empty")
