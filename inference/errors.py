"""The error of a well-formed request the model cannot process, and how it names the field, curve and point."""

from __future__ import annotations

from collections.abc import Sequence

from curve_vae.errors import InvalidInput


class InputError(InvalidInput):
    """A well-formed request the model cannot process; `loc` names the field, curve and point."""

    def __init__(self, loc: Sequence[str | int], msg: str) -> None:
        super().__init__(f"{format_loc(loc)}: {msg}")
        self.loc = tuple(loc)
        self.msg = msg


def format_loc(loc: Sequence[str | int]) -> str:
    """("curves", 2, 17, 1) -> "curves[2][17][1]"."""
    out = ""
    for part in loc:
        out += f"[{part}]" if isinstance(part, int) else (f".{part}" if out else str(part))
    return out or "body"
