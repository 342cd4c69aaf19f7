"""Request and response bodies of the v1 REST API, with the field docs and examples the OpenAPI page shows.

Only what a schema can check on its own lives here (finite numbers, [x, y] pairs, ≥ 4
points, ≥ 2 distinct points, either `steps` or `weights`). Limits that come from the
settings or the loaded model (curves per request, points per curve, latent size, weight
row length) are checked in `service.deps`, with the same error format, and stated in the
published schema by `service.openapi.state_bounds`.

Length (~570 lines): every request and response body in one place, as the OpenAPI page groups
them; the field docs are most of it.
"""

from __future__ import annotations

from typing import Annotated, Any, Literal

from pydantic import AfterValidator, BaseModel, ConfigDict, Field, model_validator
from pydantic_core import PydanticCustomError

from curve_vae.geometry import Frame

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
    Literal["auto", "model"],
    Field(
        description=(
            '"auto": each curve is shifted and uniformly scaled into the model\'s frame and results are '
            'mapped back, so curves may be anywhere at any size. "model": coordinates are already in the '
            "paper's 128×128 plane (curves about 100 units across, centred on (64, 64)) and pass untouched."
        )
    ),
]

PoseMode = Annotated[
    Literal["auto", "as_is"],
    Field(
        description=(
            '"auto" (default, with frame "auto"): each curve is tried in six poses — mirrored if it turns '
            "clockwise, its chord (first point to last) turned to -90°, -45° or -135°, each also reversed and "
            "mirrored end for end (across the line normal to the chord) — and the pose whose reconstruction is "
            "closest to the input is kept, so a curve, its reversal, mirror image and any rotation give the same "
            "curve back (6× the inference). "
            'Results come back in the caller\'s pose. "as_is": the curve is encoded as it is oriented. With frame '
            '"model" curves are always taken as they are.'
        )
    ),
]

SpacingMode = Annotated[
    Literal["parameter", "arc_length", "natural", "auto"],
    Field(
        description=(
            'How the points of a curve are read. "auto" (the default wherever curves are posted): the readings '
            'below, "parameter" and "natural" (and, where it differs, the natural reading of the fit from the points\' '
            "arc-length fractions), are all tried in every pose and the reconstruction closest to the input is kept "
            "— closer than the points as given on every family of the evaluation suite, the closest for drawn "
            "strokes, coordinate files and curves spaced by arc length, at about 3.7× the CPU of "
            '"parameter" for one curve (docs/RESULTS.md). "parameter": the points as given, interpolated along '
            "their order (the paper's curves are spaced so; 50, 161 or 500 samples of a curve give the same result) "
            '— the fast path. "natural": the curve read at even steps of the parameters of the cubic B-spline with '
            "10 control points fitted to it closest (the paper's curves' own spacing for half of them, whatever "
            'spacing they came in). "arc_length": every curve resampled evenly by arc length, and returned curves '
            "spaced so. Returned "
            'curves of `n_points` with "parameter", "natural" or "auto" (and /decode\'s and /sample\'s, whose '
            'default is "parameter") are at the model\'s own spacing: evenly in its spline parameter, or where a head '
            "that learns its points' parameters places them (GET /model: "
            "spline.learned_params)."
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
            "measured to its closest point on the curve, and the returned points are those closest points. With "
            "the default model, 10 steps bring the paper's test curves from 0.17% to 0.026% of their bounding-box "
            "diagonal, the same curves spaced by arc length from 0.28% to 0.10% and real airfoils from 0.40% to "
            "0.04%, at about 8× the compute of a plain reconstruction (3 steps: 4×; docs/RESULTS.md). "
            "Needs a model with a B-spline head; a request's work, steps × (input points + 300 per curve), is "
            "limited by the server (GET /model: limits.max_refine_work). In /encode, the returned means are the "
            "refined latents; in /interpolate the refined latents are mixed, so the ends of a sweep are the refined "
            "reconstructions "
            "(60 pairs of paper curves, the second of each spaced by arc length, 10 steps: the first end 0.026% from "
            "its input instead of 0.17%; the curves between the ends 15% rougher, as often crossing themselves)."
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
    Literal["points", "bspline", "both"],
    Field(
        description='How returned curves are given. "points" (default): `curves`, arrays of [x, y]. "bspline": '
        "`splines`, each the clamped cubic B-spline the model's B-spline head decoded (control points, knots, "
        "degree, and the parameter of each returned point: the points are the spline at those parameters, exactly). "
        '"both": `curves` and `splines`. Needs a model with a B-spline head (GET /model: `spline`).'
    ),
]

# A quarter-ellipse-like arc; any frame, any length ≥ 4: the examples work as pasted.
EXAMPLE_CURVE = [[0.0, 0.0], [1.0, 2.0], [2.5, 3.2], [4.0, 3.5], [5.5, 3.0], [7.0, 1.5], [8.0, 0.0]]
EXAMPLE_CURVE_2 = [[0.0, 0.0], [1.5, 0.5], [3.0, 2.0], [4.0, 4.0], [5.0, 6.5], [6.5, 8.0], [8.0, 8.5]]
EXAMPLE_CURVE_3 = [[0.0, 4.0], [2.0, 5.0], [4.0, 4.0], [6.0, 2.0], [8.0, 1.0], [10.0, 2.0], [12.0, 4.0]]


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


class Smoothness(BaseModel):
    """Turning angles between consecutive unit tangents (paper eq. 8), in degrees."""

    mean_turn: float | None = Field(description="Mean turning angle: how much the curve bends.")
    max_turn: float | None = Field(description="The sharpest corner.")
    roughness: float | None = Field(
        description="Mean change of turning angle between neighbouring points: near 0 for a smooth curve, "
        "large where tangents jitter."
    )


class CurveMetrics(BaseModel):
    """Quality of one returned curve, measured in the frame it is returned in (null: beyond float64)."""

    smoothness: Smoothness
    self_intersects: bool = Field(description="Whether the open polyline crosses or touches itself.")
    length: float | None = Field(description="Polyline length, in the curve's own units.")


MetricsOut = Annotated[
    list[CurveMetrics] | None,
    Field(description="One entry per returned curve, in order; present only when the request asks for `metrics`."),
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


class EncodeRequest(_Request):
    """Curves to encode into the latent space."""

    curves: list[Curve] = Field(min_length=1, description="One or more curves (at most CURVE_VAE_MAX_CURVES).")
    frame: FrameMode = "auto"
    pose: PoseMode = "auto"
    spacing: SpacingMode = "auto"
    refine: RefineSteps = 0


class EncodeResponse(BaseModel):
    mean: list[list[float]] = Field(description="Latent mean of each curve (batch × latent_dim).")
    log_var: list[list[float]] = Field(description="Latent log-variance of each curve (batch × latent_dim).")
    frames: list[FrameInfo] | None = Field(
        description='The frame each curve was mapped from (frame "auto"); pass them to /decode to map back. '
        'null for frame "model".'
    )


class DecodeRequest(_Request):
    """Latent vectors to decode into curves."""

    latents: list[list[FiniteFloat]] = Field(
        min_length=1, description="One or more latent vectors, each of the model's latent_dim (see GET /model)."
    )
    n_points: NPoints = None
    spacing: SpacingMode = "parameter"
    frames: list[FrameInfo] | None = Field(
        None,
        description="Optional frame per latent (as /encode returns them): curves are mapped into it. "
        "Omitted: curves come back in the model's 128×128 plane.",
    )
    output: OutputMode = "points"
    metrics: MetricsFlag = False


class SplineOut(BaseModel):
    """A returned curve as a clamped cubic B-spline, in the frame the curve is returned in."""

    control_points: list[tuple[float, float]] = Field(description="n_ctrl control points [x, y].")
    knots: list[float] = Field(description="Clamped uniform knot vector on [0, 1], n_ctrl + degree + 1 entries.")
    degree: int = Field(description="3: cubic.")
    params: list[float] = Field(
        description="The spline parameter in [0, 1] of each point of the returned curve, in order."
    )


class CurvesResponse(BaseModel):
    curves: list[list[tuple[float, float]]] | None = Field(
        None, description='Curves as arrays of [x, y] points (output "points" or "both").'
    )
    splines: list[SplineOut] | None = Field(
        None, description='The same curves as B-splines, one per curve (output "bspline" or "both").'
    )
    metrics: MetricsOut = None


class ReconstructRequest(_Request):
    """Curves to pass through the VAE (encode the latent mean, decode it)."""

    curves: list[Curve] = Field(min_length=1, description="One or more curves (at most CURVE_VAE_MAX_CURVES).")
    frame: FrameMode = "auto"
    pose: PoseMode = "auto"
    spacing: SpacingMode = "auto"
    refine: RefineSteps = 0
    n_points: NPoints = None
    output: OutputMode = "points"
    metrics: MetricsFlag = False


class ReconstructResponse(CurvesResponse):
    mse: list[float] = Field(
        description="Per curve: mean squared error over points and coordinates (paper eq. 4) between the input and "
        "its reconstruction at the input's own points, in the caller's frame: each input point against the returned "
        "point matched to it (with the shipped model's closest placement, its closest point on the reconstruction; "
        "GET /model: spline.placement)."
    )


class InterpolateRequest(_Request):
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
    frame: FrameMode = "auto"
    pose: PoseMode = "auto"
    spacing: SpacingMode = "auto"
    refine: RefineSteps = 0
    n_points: NPoints = None
    output: OutputMode = "points"
    metrics: MetricsFlag = False

    @model_validator(mode="after")
    def _steps_or_weights(self) -> InterpolateRequest:
        if {"steps", "weights"} <= self.model_fields_set:  # both given, even as null: the schema's "not required"
            raise PydanticCustomError("steps_and_weights", "give either steps or weights, not both")
        return self


class InterpolateResponse(CurvesResponse):
    weights: list[list[float]] = Field(description="The weight row of each returned curve, one entry per input curve.")
    frames: list[FrameInfo] | None = Field(
        description='Frame "auto": the blend of the inputs\' frames each interpolant was mapped into.'
    )


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


class SampleRequest(_Request):
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
    prior: Literal["learned", "standard"] | None = Field(
        None,
        description='"learned": the Gaussian mixture fitted to the latent means of the training curves, shipped '
        "with the model: curves like the data. \"standard\": the VAE's prior N(0, I), which the encoder's latents "
        "do not fill (small, tangled curves). Omitted: learned where the model ships it (GET /model: prior).",
    )
    valid: bool = Field(
        True,
        strict=True,
        description="Reject and redraw a curve that crosses itself or leaves the disc the data lies in (as the "
        "paper's generator rejects self-intersecting curves), at most 10 draws per curve; the seed still decides "
        "every curve. false: keep every draw.",
    )
    n_points: NPoints = None
    spacing: SpacingMode = "parameter"
    frame: FrameInfo | None = Field(
        None,
        description="Map every curve into this frame (centre and size, e.g. one /encode returned). Omitted: the "
        "model's 128×128 plane.",
    )
    output: OutputMode = "points"
    metrics: MetricsFlag = False


class SampleResponse(CurvesResponse):
    latents: list[list[float]] = Field(description="The latent vector each curve was decoded from.")
    seed: int = Field(description="The seed used: the request's, or the one drawn for it.")
    prior: Literal["learned", "standard"] = Field(description="The distribution the latents were drawn from.")
    rejected: int = Field(description="Draws rejected (self-intersecting or outside the disc) and drawn again.")
    invalid: int = Field(description="Curves still invalid after 10 draws each (returned as drawn; normally 0).")


class AugmentRequest(_Request):
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
    mode: Literal["pair", "triplet"] = Field(
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
    format: Literal["json", "npy"] = Field(
        "json",
        description='"json": curves with their sources and weights. "npy": a binary .npy file of the curves '
        "alone, float32 of shape (count, points, 2), streamed so that any count stays in bounded memory; "
        "the same request with format json (paged) gives the sources and weights.",
    )
    frame: FrameMode = "auto"
    pose: PoseMode = "auto"
    spacing: SpacingMode = "auto"
    n_points: NPoints = None
    output: OutputMode = "points"
    metrics: MetricsFlag = False


class AugmentResponse(CurvesResponse):
    sources: list[list[int]] = Field(
        description="Indices into the request's `curves` of each new curve's sources: its anchor first."
    )
    weights: list[list[float]] = Field(
        description="Weight of each source, in the order of `sources`: each ≥ 0, each row summing to 1."
    )
    frames: list[FrameInfo] | None = Field(description='Frame "auto": the blend of the sources\' frames.')
    seed: int = Field(description="The seed used: the request's, or the one drawn for it (to repeat or page on).")
    offset: int = Field(description="Index of the first returned curve in the seeded sequence.")


class FitRequest(_Request):
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
    param: Literal["chord", "uniform"] = Field(
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


class BSplineOut(BaseModel):
    control_points: list[tuple[float, float]] = Field(description="n_ctrl control points [x, y].")
    knots: list[float] = Field(description="Clamped uniform knot vector on [0, 1], n_ctrl + degree + 1 entries.")
    degree: int = Field(description="3: cubic.")
    n_ctrl: int = Field(description="Number of control points (given, or chosen by the tolerance).")
    rms_error: float = Field(description="Root mean squared distance of the points from the spline at their parameter.")
    max_error: float = Field(description="Largest such distance.")
    curve: list[tuple[float, float]] | None = Field(None, description="The spline at `n_points`, when asked for.")


class FitResponse(BaseModel):
    fits: list[BSplineOut] = Field(description="One fit per input curve, in order.")


class RevolveRequest(_Request):
    """A profile curve to turn into a surface of revolution (paper Fig. 12: a vase)."""

    curve: Curve = Field(description="The profile: ordered [x, y] points, all on one side of the axis.")
    segments: int = Field(64, ge=3, le=100_000, strict=True, description="Angular resolution: vertices per ring.")
    axis: Literal["x", "y"] = Field(
        "y", description='Revolve about a vertical line x = axis_position ("y") or a horizontal one ("x").'
    )
    axis_position: FiniteFloat | None = Field(
        None,
        description="Where that line is. Omitted: through the profile's nearest point, so the whole profile lies on "
        "one side. Profile points on the axis become poles: a profile whose ends touch it gives a closed, "
        "watertight surface.",
    )
    format: Literal["obj", "stl"] = Field("obj", description='"obj": Wavefront OBJ text. "stl": binary STL.')


class ErrorItem(BaseModel):
    loc: str = Field(description='Where: field, curve and point, e.g. "curves[2][17][1]".')
    msg: str = Field(description="What is wrong there.")


class ErrorResponse(BaseModel):
    detail: str = Field(description="One line naming the bad field, curve and point, and what is wrong.")
    errors: list[ErrorItem] = Field(default_factory=list, description="Every problem found, first one first.")


class StatusResponse(BaseModel):
    status: str


class FileInfo(BaseModel):
    sha256: str
    bytes: int


class ModelInfo(BaseModel):
    name: str
    version: str = Field(description="The model's own version (its manifest's).")
    service_version: str = Field(
        description="The curve-vae package serving it: the version `curve-vae --version` and the OpenAPI document tell."
    )
    created: str | None = None
    variant: str | None = None
    n_points: int = Field(description="Points per curve the model sees (161).")
    latent_dim: int = Field(description="Length of every latent vector.")
    model_size: float = Field(description='Bounding-box size curves are scaled to by frame "auto".')
    prior: dict[str, Any] | None = Field(
        None, description="The learned latent distribution /sample draws from by default, when the model ships one."
    )
    spline: dict[str, Any] | None = Field(
        None,
        description='The decoder\'s B-spline head (n_ctrl, degree, knots), when it has one: output "bspline" works. '
        "learned_params: whether the head places its points at parameters of its own (the spacing of the curve it "
        "decodes) rather than evenly in the spline parameter. placement: how a reconstruction's points are placed on "
        "its spline: \"closest\", each at the closest point to the input's point, whatever the input's spacing (the "
        "shipped model's); \"index\", at the model's own spacing, point i at the head's parameter i.",
    )
    files: dict[str, FileInfo] = Field(description="sha256 and size of each exported file, from the manifest.")
    providers: list[str] = Field(description="onnxruntime execution providers the sessions actually run on.")
    requested_providers: Literal["cpu", "cuda", "auto"]
    onnxruntime: str
    metrics: dict[str, Any] | None = Field(None, description="Evaluation results recorded at export, when present.")
    limits: dict[str, int] = Field(description="Request limits of this server.")
    execution: dict[str, Any] = Field(
        description="How this worker runs inference, read back from the live onnxruntime sessions: session pairs, "
        "intra- and inter-op threads, spinning; and the inference threads (slots) and micro-batching in use."
    )
