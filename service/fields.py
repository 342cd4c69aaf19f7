"""The field types of the v1 request bodies, each with the documentation the OpenAPI page shows: numbers, points,
curves, the reading's choices, seeds, frames (service.schemas builds the requests of them)."""

from __future__ import annotations

from typing import Annotated, Any

from pydantic import AfterValidator, BaseModel, ConfigDict, Field, model_validator
from pydantic_core import PydanticCustomError

from curve_vae.geometry import Frame
from curve_vae.inference import choices

FiniteFloat = Annotated[float, Field(strict=True, allow_inf_nan=False)]  # numbers only: no "1.5", no true

Point = Annotated[tuple[FiniteFloat, FiniteFloat], Field(description="[x, y]")]


def _distinct(curve: list[tuple[float, float]]) -> list[tuple[float, float]]:
    first = curve[0]
    if all(p == first for p in curve):
        raise PydanticCustomError(
            "distinct_points", "all {n} points coincide: a curve needs at least 2 distinct points", {"n": len(curve)}
        )
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

FrameMode = Annotated[
    choices.FrameMode,
    Field(
        description=(
            '"auto": each curve is shifted and uniformly scaled into the model\'s frame and results are '
            'mapped back, so curves may be anywhere at any size. "model": coordinates are already in the '
            "paper's 128×128 plane (curves about 100 units across, centred on (64, 64)) and pass untouched."
        )
    ),
]

PoseMode = Annotated[
    choices.Pose,
    Field(
        description=(
            'How a curve is turned before it is encoded (frame "auto"). "auto" (default): the reading the model was '
            'trained for (GET /model: reading.pose). "canonical": one pose the curve, its reversal, its mirror image '
            "and every rotation of it share — mirrored if it turns clockwise, its chord (first point to last) turned "
            "straight down, and reversed and mirrored end for end where its centre of mass lies towards its start — "
            'so all of them give the same curve back, at the cost of one encoding. "search": six poses (the chord '
            "turned to -90°, -45° or -135°, each also reversed and mirrored end for end) encoded and decoded, the "
            'reconstruction closest to the input kept (6× the inference). "learned": the same candidates (and, with '
            "spacing \"search\", each one's natural reading) ranked by the model's reading ranker from their points, "
            "only the first two encoded and the closer kept (2× the inference; needs a model with a ranker, GET "
            '/model: ranker). "as_is": the curve as it is listed. '
            'Results come back in the caller\'s pose. With frame "model" curves are taken as they are.'
        )
    ),
]

SpacingMode = Annotated[
    choices.Spacing,
    Field(
        description=(
            'How the points of a curve are read along it. "auto" (default): the model\'s own reading (GET /model: '
            'reading.spacing). "parameter": the points as given, interpolated along their order (50, 161 or 500 '
            'samples of a curve give the same result). "natural": the curve read at even steps of the parameters '
            "of the cubic B-spline with 10 control points fitted to it closest (the paper's curves' own spacing, "
            'whatever spacing they came in). "arc_length": every curve resampled evenly by arc length, and returned '
            'curves spaced so. "search": "parameter" and each natural reading tried, the reconstruction closest to '
            "the input kept (2–3× the inference). Returned curves of `n_points` are at the model's own spacing "
            '(evenly in its spline parameter) except with "arc_length".'
        )
    ),
]

#: Most fitting steps a request may ask for (each costs about 7 decoder runs per curve: a Jacobian of 32 runs every
#: 5th step, one run per step; inference/fitting.py).
MAX_REFINE_STEPS = 30

RefineSteps = Annotated[
    int,
    Field(
        ge=0,
        le=MAX_REFINE_STEPS,
        strict=True,
        description=(
            "Fitting steps (default 0: none). After encoding, each curve's latent is refined by this many "
            "Levenberg–Marquardt steps that bring the decoded curve closer to the input's own points, each point "
            "measured to its closest point on the curve, and the returned points are those closest points: a closer "
            "fit for several times the compute of a plain reconstruction (docs/RESULTS.md has the trade-off). "
            "Needs a model with a B-spline head; a request's work, steps × (input points + 300 per curve), is "
            "limited by the server (GET /model: limits.max_refine_work). In /encode, the returned means are the "
            "refined latents; in /interpolate the refined latents are mixed, so the ends of a sweep are the refined "
            "reconstructions."
        ),
    ),
]

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

    center: tuple[FiniteFloat, FiniteFloat] = Field(description="Bounding-box centre [x, y].")
    size: Annotated[
        float, Field(gt=0, strict=True, allow_inf_nan=False, description="Larger side of the bounding box.")
    ]
    rotation: FiniteFloat = Field(
        0.0, description="Radians, counter-clockwise, the curve was turned by (after `mirror`) to reach the model."
    )
    mirror: bool = Field(False, strict=True, description="Whether it was mirrored (x -> -x about `center`) first.")
    reverse: bool = Field(False, strict=True, description="Whether the curve's point order was reversed.")

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
