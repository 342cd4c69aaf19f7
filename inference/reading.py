"""How a caller's curves are read: one value for the frame, pose, spacing and fitting steps a request asks for.

    Reading()                                  # the model's own reading: what it was trained for
    Reading(pose="search", spacing="search")   # the search: several poses and spacings, the closest kept
    Reading(frame="model")                     # points already in the paper's 128×128 plane, taken as they are

"auto" pose and spacing mean the model's own (its manifest's `reading`): one encoding per curve for a model
trained in geometry.canonical_frame's pose, the search for models exported before that. `resolved` makes that
concrete, so everything past it sees one of the explicit values.
"""

from __future__ import annotations

from dataclasses import dataclass, field, fields, replace
from functools import cache
from typing import Any, get_args, get_type_hints

from curve_vae.inference.choices import FRAME, LOOKS, POSE, REFINE, SPACING, FrameMode, Option, Pose, Spacing
from curve_vae.inference.errors import InputError
from curve_vae.inference.manifest import ReadingSpec


@dataclass(frozen=True)
class Reading:
    """The one definition of the reading options: the request schema (service.schemas.ReadingIn), the command line's
    flags (commands.options.add_reading_options) and the client's typed parameters are derived from these fields
    and the `Option` each carries (inference.choices)."""

    frame: FrameMode = field(default="auto", metadata={"option": FRAME})
    pose: Pose = field(default="auto", metadata={"option": POSE})
    spacing: Spacing = field(default="auto", metadata={"option": SPACING})
    looks: int = field(default=1, metadata={"option": LOOKS})  # fixed-point steps after reading (inference.looking)
    refine: int = field(default=0, metadata={"option": REFINE})  # Levenberg–Marquardt steps (inference.fitting)

    def __post_init__(self) -> None:
        for o in reading_options():
            value = getattr(self, o.name)
            if o.values and value not in o.values:
                raise InputError((o.name,), f"{value!r} is not one of {', '.join(map(repr, o.values))}")
            if not o.values and not _within(value, o.doc):
                raise InputError((o.name,), f"expected an integer from {o.doc.ge} to {o.doc.le}, got {value!r}")

    def resolved(self, model: ReadingSpec) -> Reading:
        """The reading with "auto" replaced by the model's own; with frame "model" curves keep their pose."""
        pose = model.pose if self.pose == "auto" else self.pose
        spacing = model.spacing if self.spacing == "auto" else self.spacing
        return replace(self, pose="as_is" if self.frame == "model" else pose, spacing=spacing)

    @property
    def searches(self) -> bool:
        """Whether several candidates are encoded per curve (the pose or the spacing searched)."""
        return self.pose in ("search", "learned") or self.spacing == "search"

    @property
    def key(self) -> str:
        """The reading as a cache key."""
        return f"{self.frame}/{self.pose}/{self.spacing}/{self.looks}/{self.refine}"


def _within(value: object, doc: Option) -> bool:
    """An integer (not a bool) within the option's bounds."""
    if type(value) is not int:
        return False
    return (doc.ge is None or value >= doc.ge) and (doc.le is None or value <= doc.le)


@dataclass(frozen=True)
class ReadingOption:
    """One field of `Reading` as a front end needs it: its name, type, default, values (none for an integer) and
    documentation."""

    name: str
    kind: Any  # the Literal of its values, or int
    default: Any
    values: tuple[str, ...]
    doc: Option


@cache
def reading_options() -> tuple[ReadingOption, ...]:
    """`Reading`'s fields, in order."""
    hints = get_type_hints(Reading)
    return tuple(
        ReadingOption(f.name, hints[f.name], f.default, get_args(hints[f.name]), f.metadata["option"])
        for f in fields(Reading)
    )
