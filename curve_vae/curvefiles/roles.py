"""The roles of a drawing's curves, one rule for every reader (and for the page's, service/static/files.js): a curve
is an `input` (drawn or given), a `reconstruction` (of an input, named by `of`) or an `interpolant` (a mix of the
inputs, by its `weights`). Where a file marks roles and holds inputs, its inputs are its curves and the others are
derived, left aside with a warning saying how many; where it marks roles but holds no input (a command's own output
of reconstructions), every curve is read; a file without roles is read whole."""

from __future__ import annotations

from collections.abc import Iterable
from typing import Any, NamedTuple

from curve_vae.curvefiles.common import warn

ROLES = ("input", "reconstruction", "interpolant")


class Found(NamedTuple):
    """One curve of a file: a label for messages (`path#id`, `SPLINE #1A`), its points and its role (None: unmarked)."""

    label: str
    points: Any
    role: str | None = None


def role_of(marks: str | None) -> str | None:
    """The role among a mark's words (an SVG class `input`), or None."""
    return next((word for word in (marks or "").split() if word in ROLES), None)


def derived_note(name: str, inputs: int, derived: int) -> str:
    """What a reader says of the derived curves it leaves aside (the page says the same)."""
    return (
        f"{name}: its {inputs} input curve(s) read; {derived} derived curve(s) (reconstructions, interpolants) "
        "not read as inputs"
    )


def the_inputs(found: Iterable[Found], name: str) -> list[Found]:
    """The curves a file gives by the rule above, in the file's order."""
    found = list(found)
    inputs = [f for f in found if f.role == "input"]
    if not inputs:
        return found
    if len(inputs) < len(found):
        warn(derived_note(name, len(inputs), len(found) - len(inputs)))
    return inputs
