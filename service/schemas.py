"""Request bodies of the v1 REST API, with the field docs and examples the OpenAPI page shows (field types:
service.fields; responses: inference.answers and service.responses).

Only what a schema can check on its own lives here (finite numbers, [x, y] pairs, ≥ 4 points, ≥ 2 distinct points,
either `steps` or `weights`); the limits that come from the settings are service.limits'. The fields every curve
request shares are written once: `CurvesIn` (the curves), `ReadingIn` (how they are read: one `Reading`) and
`OutputIn` (how results come back). The choices are inference.choices'.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from pydantic import BaseModel, Field, create_model, model_validator
from pydantic_core import PydanticCustomError

from curve_vae.inference import choices
from curve_vae.inference.choices import MAX_REFINE_STEPS  # noqa: F401  (part of the schemas' API)
from curve_vae.inference.reading import Reading, reading_options
from curve_vae.service.fields import (  # noqa: F401  (FrameInfo: part of the schemas' API)
    MAX_SAFE_INTEGER,
    Curve,
    DecodedSpacing,
    FiniteFloat,
    FrameInfo,
    MetricsFlag,
    NPoints,
    OutputMode,
    PriorName,
    Seed,
    _Request,
    reading_field,
)


class CurvesIn(_Request):
    """One or more curves."""

    curves: list[Curve] = Field(min_length=1, description="One or more curves (at most CURVE_VAE_MAX_CURVES).")


class _ReadingFields(BaseModel):
    """How a request's curves are read into the model: one field per option of inference.reading.Reading."""

    def reading(self) -> Reading:
        return Reading(**{o.name: getattr(self, o.name) for o in reading_options()})


# The fields are Reading's, made here rather than written again (frame, pose, spacing, refine: their values, bounds,
# defaults and descriptions); the type checker sees the base, and reads the options through `reading()`.
if TYPE_CHECKING:
    ReadingIn = _ReadingFields
else:
    ReadingIn = create_model(
        "ReadingIn",
        __base__=_ReadingFields,
        __doc__=_ReadingFields.__doc__,
        __module__=__name__,
        **{o.name: reading_field(o) for o in reading_options()},
    )


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
    spacing: DecodedSpacing = "parameter"
    frames: list[FrameInfo] | None = Field(
        None,
        description="Optional frame per latent (as /encode returns them): curves are mapped into it. "
        "Omitted: curves come back in the model's 128×128 plane.",
    )


class ExploreRequest(CurvesIn, ReadingIn, OutputIn):
    """One curve whose neighbours along the directions the data varies most are decoded."""

    curves: list[Curve] = Field(
        min_length=1, max_length=1, description="The one curve to explore around, as a list of one curve."
    )
    steps: int = Field(
        3,
        ge=2,
        le=9,
        strict=True,
        description="Offsets per direction, evenly from −spread to spread: steps**directions curves (3 and 2: a 3×3 "
        "grid whose middle is the curve's own reconstruction).",
    )
    spread: float = Field(
        1.0,
        gt=0,
        le=4,
        strict=False,
        allow_inf_nan=False,
        description="The largest offset, in standard deviations of the latent distribution along each direction.",
    )
    directions: int = Field(
        2, ge=1, le=4, strict=True, description="How many principal directions, the largest variance first."
    )
    prior: PriorName = Field(
        None,
        description="The latent distribution whose principal directions are followed, as /sample names them "
        '(omitted: learned where the model ships it; "standard": the latent\'s first axes).',
    )

    @model_validator(mode="after")
    def _not_too_many(self) -> ExploreRequest:
        if self.steps**self.directions > 256:
            raise PydanticCustomError(
                "too_many", "steps**directions curves would be {n}; at most 256", {"n": self.steps**self.directions}
            )
        return self


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
    prior: PriorName = Field(
        None,
        description='"learned": the Gaussian mixture fitted to the latent means of the training curves, shipped '
        "with the model: curves like the data. \"standard\": the VAE's prior N(0, I), which the encoder's latents "
        "do not fill (small, tangled curves). Any other name: a prior fitted to a user's own curves and loaded "
        "by the server (GET /model: priors). Omitted: learned where the model ships it (GET /model: prior).",
    )
    offset: int = Field(
        0,
        ge=0,
        le=MAX_SAFE_INTEGER,
        strict=True,
        description="Index of the first curve in the seeded sequence: item i depends only on (seed, i), so pages "
        "`offset`=0, 256, 512… of `count`=256 are the curves of one larger request.",
    )
    valid: bool = Field(
        True,
        strict=True,
        description="Reject and redraw a curve that crosses itself or leaves the disc the data lies in (as the "
        "paper's generator rejects self-intersecting curves), at most 10 draws per curve; the seed still decides "
        "every curve. false: keep every draw.",
    )
    spacing: DecodedSpacing = "parameter"
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
