"""Request bodies of the v1 REST API, with the field docs and examples the OpenAPI page shows (responses:
service.responses).

Only what a schema can check on its own lives here (finite numbers, [x, y] pairs, ≥ 4 points, ≥ 2 distinct points,
either `steps` or `weights`); the limits that come from the settings are service.limits'. The fields every curve
request shares are written once: `CurvesIn` (the curves), `ReadingIn` (how they are read: one `Reading`) and
`OutputIn` (how results come back). The choices are inference.choices'.
"""

from __future__ import annotations

from typing import Annotated, Any

from pydantic import AfterValidator, BaseModel, ConfigDict, Field, model_validator
from pydantic_core import PydanticCustomError

from curve_vae.geometry import Frame
from curve_vae.inference import choices
from curve_vae.inference.reading import Reading

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
            'reconstruction closest to the input kept (6× the inference). "as_is": the curve as it is listed. '
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


class CurvesIn(_Request):
    """One or more curves."""

    curves: list[Curve] = Field(min_length=1, description="One or more curves (at most CURVE_VAE_MAX_CURVES).")


class ReadingIn(BaseModel):
    """How a request's curves are read into the model."""

    frame: FrameMode = "auto"
    pose: PoseMode = "auto"
    spacing: SpacingMode = "auto"
    refine: RefineSteps = 0

    def reading(self) -> Reading:
        return Reading(self.frame, self.pose, self.spacing, self.refine)


class OutputIn(BaseModel):
    """How a request's curves come back."""

    n_points: NPoints = None
    output: OutputMode = "points"
    metrics: MetricsFlag = False


class EncodeRequest(CurvesIn, ReadingIn):
    """Curves to encode into the latent space."""


class ReconstructRequest(CurvesIn, ReadingIn, OutputIn):
    """Curves to pass through the VAE (encode the latent mean, decode it)."""


class DecodeRequest(_Request, OutputIn):
    """Latent vectors to decode into curves."""

    latents: list[list[FiniteFloat]] = Field(
        min_length=1, description="One or more latent vectors, each of the model's latent_dim (see GET /model)."
    )
    spacing: SpacingMode = "parameter"
    frames: list[FrameInfo] | None = Field(
        None,
        description="Optional frame per latent (as /encode returns them): curves are mapped into it. "
        "Omitted: curves come back in the model's 128×128 plane.",
    )


class InterpolateRequest(CurvesIn, ReadingIn, OutputIn):
    """Curves whose latent means are mixed (paper eqs. 9 and 10)."""

    curves: list[Curve] = Field(
        min_length=2, description="Two (pair), three (triplet) or more curves whose latent means are mixed."
    )
    steps: int | None = Field(
        None,
        ge=2,
        strict=True,
        description="Even grid of weights: for a pair, `steps` curves sweeping from the first curve (weights [1, 0]) "
        "to the second ([0, 1]) inclusive; for a triplet, the barycentric grid (i, j, k)/(steps−1), "
        "steps·(steps+1)/2 curves; likewise for more curves. Default 5 when `weights` is omitted too.",
    )
    weights: list[list[FiniteFloat]] | None = Field(
        None,
        min_length=1,
        description="Explicit weight rows, one entry per input curve, each row summing to 1 (negative entries "
        "extrapolate). One interpolant per row.",
    )

    @model_validator(mode="after")
    def _steps_or_weights(self) -> InterpolateRequest:
        if {"steps", "weights"} <= self.model_fields_set:  # both given, even as null: the schema's "not required"
            raise PydanticCustomError("steps_and_weights", "give either steps or weights, not both")
        return self


class SampleRequest(_Request, OutputIn):
    """Draw new curves from the latent prior."""

    count: int = Field(ge=1, strict=True, description="How many curves (at most CURVE_VAE_MAX_CURVES).")
    seed: Seed = None
    temperature: float = Field(
        1.0,
        ge=0,
        le=100,
        strict=True,
        allow_inf_nan=False,
        description="Spread of the latents about the prior's means: each component's covariance is scaled by "
        "temperature² (standard prior: z ~ N(0, temperature²·I)). 1 is the distribution itself; below 1 stays "
        "near typical shapes, 0 gives the component means.",
    )
    prior: str | None = Field(
        None,
        pattern=r"^[A-Za-z0-9][A-Za-z0-9_.-]*$",
        max_length=100,
        description='"learned": the Gaussian mixture fitted to the latent means of the training curves, shipped '
        "with the model: curves like the data. \"standard\": the VAE's prior N(0, I), which the encoder's latents "
        "do not fill (small, tangled curves). Any other name: a prior fitted to a user's own curves and loaded "
        "by the server (GET /model: priors). Omitted: learned where the model ships it (GET /model: prior).",
    )
    valid: bool = Field(
        True,
        strict=True,
        description="Reject and redraw a curve that crosses itself or leaves the disc the data lies in (as the "
        "paper's generator rejects self-intersecting curves), at most 10 draws per curve; the seed still decides "
        "every curve. false: keep every draw.",
    )
    spacing: SpacingMode = "parameter"
    frame: FrameInfo | None = Field(
        None,
        description="Map every curve into this frame (centre and size, e.g. one /encode returned). Omitted: the "
        "model's 128×128 plane.",
    )


class AugmentRequest(CurvesIn, ReadingIn, OutputIn):
    """Make new curves between given ones: random pair or triplet interpolants of their latent means."""

    curves: list[Curve] = Field(
        min_length=2, description="Seed curves (at most CURVE_VAE_MAX_CURVES): ≥ 2 for pairs, ≥ 3 for triplets."
    )
    count: int = Field(
        ge=1,
        strict=True,
        description="How many new curves: at most CURVE_VAE_MAX_CURVES with format json (page with `offset`), "
        "CURVE_VAE_MAX_STREAM_CURVES with format npy (streamed).",
    )
    mode: choices.AugmentMode = Field(
        "pair",
        description="Mix 2 (pair, paper eq. 9) or 3 (triplet, eq. 10) distinct seed curves: a random anchor and "
        "random partners, with weights uniform on the simplex (each ≥ 0, summing to 1).",
    )
    neighbours: int | None = Field(
        None,
        ge=1,
        strict=True,
        description="Mix each anchor only with its `neighbours` nearest seed curves (Euclidean distance between "
        "latent means): near neighbours interpolate into better curves (paper §4). At least 1 for pairs, 2 for "
        "triplets, at most the number of other curves. Omitted: any curve with any other.",
    )
    seed: Seed = None
    offset: int = Field(
        0,
        ge=0,
        le=MAX_SAFE_INTEGER,
        strict=True,
        description="Index of the first new curve in the seeded sequence. Item i depends only on (seed, i), so "
        "pages `offset`=0, 100, 200… of `count`=100 are the same curves as one request of `count`=300.",
    )
    format: choices.AugmentFormat = Field(
        "json",
        description='"json": curves with their sources and weights. "npy": a binary .npy file of the curves '
        "alone, float32 of shape (count, points, 2), streamed so that any count stays in bounded memory; "
        "the same request with format json (paged) gives the sources and weights.",
    )


class FitRequest(CurvesIn):
    """Curves to approximate by least-squares cubic B-splines."""

    curves: list[Curve] = Field(min_length=1, description="One or more curves (at most CURVE_VAE_MAX_CURVES).")
    n_ctrl: int | None = Field(
        None,
        ge=4,
        strict=True,
        description="Control points of each clamped uniform cubic B-spline (10: the paper's data); at most the "
        "number of points of the curve. Omitted: the fewest (from 4 up) whose fit is within `tolerance`.",
    )
    tolerance: float = Field(
        1e-3,
        gt=0,
        le=1,
        strict=True,
        allow_inf_nan=False,
        description="Without n_ctrl: the RMS fit error to reach, as a fraction of the curve's bounding-box diagonal.",
    )
    param: choices.FitParam = Field(
        "chord",
        description='Parameter of each point: "chord" (cumulative chord length; any curve) or "uniform" (i/(n−1): '
        "samples evenly spaced in the B-spline parameter, like the paper's data, whose control points it recovers "
        "exactly).",
    )
    n_points: int | None = Field(
        None,
        ge=2,
        strict=True,
        description="Also return each fitted spline sampled at this many points, evenly in its parameter.",
    )


class RevolveRequest(_Request):
    """A profile curve to turn into a surface of revolution (paper Fig. 12: a vase)."""

    curve: Curve = Field(description="The profile: ordered [x, y] points, all on one side of the axis.")
    segments: int = Field(64, ge=3, le=100_000, strict=True, description="Angular resolution: vertices per ring.")
    axis: choices.Axis = Field(
        "y", description='Revolve about a vertical line x = axis_position ("y") or a horizontal one ("x").'
    )
    axis_position: FiniteFloat | None = Field(
        None,
        description="Where that line is. Omitted: through the profile's nearest point, so the whole profile lies on "
        "one side. Profile points on the axis become poles: a profile whose ends touch it gives a closed, "
        "watertight surface.",
    )
    format: choices.MeshFormat = Field("obj", description='"obj": Wavefront OBJ text. "stl": binary STL.')
