"""The field types of the v1 request bodies, each with the documentation the OpenAPI page shows: numbers, points,
curves, the reading's options (made from inference.reading), seeds, frames (service.schemas builds the requests)."""

from __future__ import annotations

from typing import Annotated, Any

from pydantic import AfterValidator, BaseModel, ConfigDict, Field, model_validator
from pydantic_core import PydanticCustomError

from curve_vae.geometry import Frame
from curve_vae.geometry.adapt import COINCIDENT, coincident
from curve_vae.inference import choices
from curve_vae.inference.answers import FRAME_FIELDS
from curve_vae.inference.reading import ReadingOption

FiniteFloat = Annotated[float, Field(strict=True, allow_inf_nan=False)]  # numbers only: no "1.5", no true

Point = Annotated[tuple[FiniteFloat, FiniteFloat], Field(description="[x, y]")]


def _distinct(curve: list[tuple[float, float]]) -> list[tuple[float, float]]:
    if coincident([curve])[0]:
        raise PydanticCustomError("distinct_points", COINCIDENT, {"n": len(curve)})
    return curve


Curve = Annotated[
    list[Point],
    Field(
        min_length=4,
        description="Ordered [x, y] points of a curve: ≥ 4 points, ≥ 2 of them distinct. A curve whose last point "
        "repeats its first is closed (a loop, as closed airfoil files list it): its reconstruction, and every "
        "interpolant between closed curves, comes back closed.",
    ),
    AfterValidator(_distinct),
]


def reading_field(option: ReadingOption) -> tuple[Any, Any]:
    """A request field for one of the reading's options (inference.reading): its values or bounds and its
    description, as `pydantic.create_model` takes them (service.schemas.ReadingIn)."""
    doc = option.doc
    description = doc.description(option.default)
    if option.values:
        field = Field(description=description)
    else:  # an integer option: its bounds, strictly
        field = Field(description=description, ge=doc.ge, le=doc.le, strict=True)
    return Annotated[option.kind, field], option.default


#: How /decode and /sample space the curves they return (no input to read): "parameter" by default.
DecodedSpacing = Annotated[choices.Spacing, Field(description=choices.SPACING.description("parameter"))]

NPoints = Annotated[
    int | None,
    Field(
        ge=4,
        strict=True,
        description=(
            "Points per returned curve (at most CURVE_VAE_MAX_POINTS), spaced as `spacing` says. Omitted: each curve "
            "comes back at its input's length and point positions (the model's 161 points where there is no single "
            "input length)."
        ),
    ),
]

OutputMode = Annotated[
    choices.Output,
    Field(
        description='How returned curves are given. "points" (default): `curves`, arrays of [x, y]. "bspline": '
        "`splines`, each the clamped cubic B-spline the model's B-spline head decoded (control points, knots, "
        "degree, and the parameter of each returned point: the points are the spline at those parameters, exactly). "
        '"both": `curves` and `splines`. Needs a model with a B-spline head (GET /model: `spline`).'
    ),
]


#: 2^53 - 1: the largest integer every JSON parser (JavaScript's included) holds exactly; seeds and offsets stay below.
MAX_SAFE_INTEGER = 2**53 - 1


class _Request(BaseModel):
    model_config = ConfigDict(extra="forbid")  # a misspelt field is an error, not silently ignored

    @model_validator(mode="before")
    @classmethod
    def _integral_numbers(cls, data: Any) -> Any:
        """139.0 is the integer 139 in JSON (and in JSON Schema's "integer"); 139.5, "139" and true stay errors."""
        if not isinstance(data, dict):
            return data
        ints = {name for name, f in cls.model_fields.items() if f.annotation in (int, int | None)}
        return {
            k: int(v) if k in ints and isinstance(v, float) and v.is_integer() and abs(v) < 2**63 else v
            for k, v in data.items()
        }


MetricsFlag = Annotated[
    bool,
    Field(
        strict=True,
        description="Also report each returned curve's smoothness (paper §3.4), self-intersection and length "
        "(`metrics` in the response).",
    ),
]


class FrameInfo(BaseModel):
    """Where a curve lives: centre of its bounding box and its larger side; and the pose that turned it into the
    model's orientation (pose "auto"). Mapping into a frame applies the pose's inverse: rotation, mirror and order."""

    center: tuple[FiniteFloat, FiniteFloat] = Field(description=FRAME_FIELDS["center"])
    size: Annotated[float, Field(gt=0, strict=True, allow_inf_nan=False, description=FRAME_FIELDS["size"])]
    rotation: FiniteFloat = Field(0.0, description=FRAME_FIELDS["rotation"])
    mirror: bool = Field(False, strict=True, description=FRAME_FIELDS["mirror"])
    reverse: bool = Field(False, strict=True, description=FRAME_FIELDS["reverse"])

    def frame(self) -> Frame:
        return Frame(self.center, self.size, self.rotation, self.mirror, self.reverse)


Seed = Annotated[
    int | None,
    Field(
        ge=0,
        le=MAX_SAFE_INTEGER,
        strict=True,
        description="Seed of the random draws: the same request and seed give the same answer. Omitted: fresh "
        "randomness, and the response reports the seed it drew.",
    ),
]


#: A latent distribution by name, as /sample and /explore take it and GET /model lists them: "learned" (shipped with
#: the model), "standard" (N(0, I)) or a prior fitted to a user's curves.
PriorName = Annotated[str | None, Field(pattern=r"^[A-Za-z0-9][A-Za-z0-9_.-]*$", max_length=100)]
