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

#: The page's colours, a curve's by the order of its name (A, B, …, Z, AA, …) for life; the same list is the page's
#: (service/static/files.js, `PALETTE`; a test keeps the two equal). DXF has no RGB on a layer's colour index: ACI,
#: the nearest of AutoCAD's colours to each.
PALETTE = ("#1f77b4", "#2ca02c", "#9467bd", "#ff7f0e", "#17becf", "#8c564b", "#e377c2", "#bcbd22", "#7f7f7f", "#393b79")
PALETTE_ACI = (5, 3, 6, 30, 4, 34, 221, 52, 8, 176)
INTERPOLANT_COLOUR, INTERPOLANT_ACI = "#d62728", 1


def curve_name(k: int) -> str:
    """The k-th curve's name, from 0: A, B, …, Z, AA, AB, … (as the page names curves)."""
    name, k = "", k + 1
    while k > 0:
        k, r = divmod(k - 1, 26)
        name = chr(65 + r) + name
    return name


def name_index(name: str) -> int | None:
    """The order of a curve's name (`curve_name`'s inverse), or None for a name of another kind."""
    if not name or not name.isascii() or not name.isalpha() or not name.isupper():
        return None
    k = 0
    for c in name:
        k = 26 * k + ord(c) - 64
    return k - 1


def colour_index(mark: dict[str, Any]) -> int | None:
    """Where a marked curve's colour is in PALETTE: its own name's, or its input's (`of`) for a reconstruction."""
    k = name_index(str(mark.get("of") or mark.get("name") or ""))
    return None if k is None else k % len(PALETTE)


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
