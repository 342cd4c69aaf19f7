"""How a caller's curves are read: one value for the frame, pose, spacing and fitting steps a request asks for.

    Reading()                                  # the model's own reading: what it was trained for
    Reading(pose="search", spacing="search")   # the search: several poses and spacings, the closest kept
    Reading(frame="model")                     # points already in the paper's 128×128 plane, taken as they are

"auto" pose and spacing mean the model's own (its manifest's `reading`): one encoding per curve for a model
trained in geometry.canonical_frame's pose, the search for models exported before that. `resolved` makes that
concrete, so everything past it sees one of the explicit values.

The candidates (below) are what a resolved reading means for one curve: each pose and spacing it tries, with its
points in the model's plane.
"""

from __future__ import annotations

from dataclasses import dataclass, field, fields, replace
from functools import cache
from typing import Any, NamedTuple, get_args, get_type_hints

import numpy as np

from curve_vae.geometry import BeyondFloat32, Frame, to_model_plane
from curve_vae.geometry.adapt import F32_MAX
from curve_vae.geometry.batch import FrameRows, Ragged
from curve_vae.geometry.frame import resample_index
from curve_vae.inference.choices import FRAME, LOOKS, POSE, REFINE, SPACING, FrameMode, Option, Pose, Spacing
from curve_vae.inference.errors import InputError
from curve_vae.inference.model.manifest import ReadingSpec


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


# The search's candidates: the ways of reading one curve (a pose, a spacing, its natural parameters) and each one's
# points in the model's plane, all of a request's candidates at once where their spacings allow (inference.reader
# makes them and keeps the closest).
#


class Candidate(NamedTuple):
    """One way of reading one curve: its frame (with the pose), its spacing and natural parameters."""

    curve: int  # which of the curves read
    frame: Frame | None
    spacing: str
    natural: np.ndarray | None  # the natural reading's parameters, with spacing "natural"
    pose: int  # which of the curve's pose candidates (in a shared set, candidate k is one pose for every curve)


def model_points(
    inputs: list[np.ndarray], index: list[int], stage: list[Candidate], *, n_points: int, model_size: float
) -> tuple[np.ndarray, list[np.ndarray | None]]:
    """Each candidate's model-plane points (k, n_points, 2) float32 and where its curve's points sit along them: all
    at once where every candidate reads its points as given (`_as_given`) or at a natural reading (`_read`), else one
    by one (`geometry.to_model_plane`)."""
    if stage and all(c.spacing == "parameter" for c in stage):
        return _as_given(inputs, index, stage, n_points=n_points, model_size=model_size)
    if stage and all(c.spacing in ("parameter", "natural") and c.frame is not None for c in stage):
        return _read(inputs, index, stage, n_points=n_points, model_size=model_size)
    rows, fractions = [], []
    with np.errstate(all="ignore"):
        for c, f, spacing, natural, _ in stage:
            try:
                m, fraction = to_model_plane(
                    inputs[c], f, model_size=model_size, n_points=n_points, spacing=spacing, natural=natural
                )
            except BeyondFloat32:
                raise InputError(("curves", index[c]), _beyond(f is not None)) from None
            rows.append(m)
            fractions.append(fraction)
    batch = np.stack(rows).astype(np.float32) if rows else np.zeros((0, n_points, 2), np.float32)
    return batch, fractions


def _as_given(
    inputs: list[np.ndarray], index: list[int], stage: list[Candidate], *, n_points: int, model_size: float
) -> tuple[np.ndarray, list[np.ndarray | None]]:
    """`geometry.to_model_plane` with spacing "parameter" for every candidate at once: each curve through its frame
    (geometry.batch), then the curves of each length to the model's count along their point index."""
    curves = Ragged.of([inputs[c.curve] for c in stage])
    framed = [c.frame for c in stage]
    with np.errstate(all="ignore"):
        frames = [f for f in framed if f is not None]
        if len(frames) == len(framed):  # every candidate has a frame
            flat = FrameRows.of(frames).to_model(curves, model_size)
        else:
            flat = np.concatenate(
                [f.to_model(p, model_size) if f is not None else p for f, p in zip(framed, curves.split(curves.points))]
            )
        out = np.empty((len(stage), n_points, 2))
        parts = curves.split(flat)
        for n in np.unique(curves.lengths):
            rows = np.flatnonzero(curves.lengths == n)
            out[rows] = resample_index(np.stack([parts[r] for r in rows]), n_points)
    _check_float32(out, stage, index)
    fractions = [None if n == n_points else np.linspace(0.0, 1.0, n) for n in curves.lengths]
    return out.astype(np.float32), fractions


def _read(
    inputs: list[np.ndarray], index: list[int], stage: list[Candidate], *, n_points: int, model_size: float
) -> tuple[np.ndarray, list[np.ndarray | None]]:
    """`geometry.to_model_plane` with spacing "parameter" or "natural" for every candidate at once: each reading of a
    curve taken to the model's count once, in the caller's plane (a frame maps interpolated points as it maps the
    points), then every candidate through its frame (geometry.batch)."""
    grid = np.linspace(0.0, 1.0, n_points)
    # (curve, its reading's id, reversed): a curve's poses share its readings, each read in the model's order (so
    # that a curve and its reversal are read alike to the last bit)
    read: dict[tuple[int, int, bool], np.ndarray] = {}
    rows: list[np.ndarray] = []
    fractions: list[np.ndarray | None] = []
    with np.errstate(all="ignore"):
        for c in stage:
            pts = inputs[c.curve]
            back = c.frame is not None and c.frame.reverse
            key = (c.curve, id(c.natural), back)
            if c.natural is None:
                fractions.append(None if len(pts) == n_points else np.linspace(0.0, 1.0, len(pts)))
                if key not in read:
                    read[key] = resample_index(pts[None], n_points)[0]
            else:  # where the caller's points sit, in the model's order
                where = (1.0 - c.natural)[::-1] if back else c.natural
                fractions.append(where)
                if key not in read:
                    at = where + np.arange(len(pts)) * 1e-12  # strictly increasing, for np.interp
                    ordered = pts[::-1] if back else pts
                    m = np.stack([np.interp(grid, at, ordered[:, 0]), np.interp(grid, at, ordered[:, 1])], axis=1)
                    read[key] = m[::-1] if back else m  # in the caller's order: the frame turns it round
            rows.append(read[key])
        frames = FrameRows.of([c.frame for c in stage if c.frame is not None])
        out = frames.to_model_rows(np.stack(rows), model_size)
    _check_float32(out, stage, index)
    return out.astype(np.float32), fractions


def _beyond(framed: bool) -> str:
    return (
        "its extent is too small or too large to map to the model's frame"
        if framed
        else 'coordinates beyond float32 range; use frame "auto"'
    )


def _check_float32(out: np.ndarray, stage: list[Candidate], index: list[int]) -> None:
    """Names the first candidate's curve whose model-plane points (k, n, 2) are not all finite float32 numbers."""
    bad = ~(np.abs(out) <= F32_MAX).reshape(len(out), -1).all(axis=1)  # also true for inf and nan
    if bad.any():
        k = int(np.argmax(bad))
        raise InputError(("curves", index[stage[k].curve]), _beyond(stage[k].frame is not None))
