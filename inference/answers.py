"""What each call answers as JSON: the shape of every body, named and described once.

Each shape is a TypedDict whose fields carry the docs the OpenAPI page shows. inference.results builds the bodies as
these types (the type checker holds every key and value to them), the service's routes declare them as their
`response_model` (so the schema on the page is this one), and `curve-vae encode|reconstruct|sample|augment|fit`
write the same bodies. Arrays may stay numpy where a body is built (orjson writes them directly); `NumpyJson` gives
such a field the schema of the lists it is written as.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Annotated, Any, NotRequired

import numpy as np
from pydantic import Field, GetCoreSchemaHandler, GetJsonSchemaHandler, TypeAdapter
from pydantic.json_schema import JsonSchemaValue
from pydantic_core import core_schema
from typing_extensions import TypedDict

Point = tuple[float, float]


@dataclass(frozen=True)
class NumpyJson:
    """A field that may hold numpy arrays, documented as the JSON lists `like` they are written as (never validated:
    bodies are built by this package, not read)."""

    like: Any

    def __get_pydantic_core_schema__(self, source: Any, handler: GetCoreSchemaHandler) -> core_schema.CoreSchema:
        return core_schema.any_schema()

    def __get_pydantic_json_schema__(
        self, schema: core_schema.CoreSchema, handler: GetJsonSchemaHandler
    ) -> JsonSchemaValue:
        return TypeAdapter(self.like).json_schema()


#: numbers as a body holds them: a numpy array, or (nested) lists
Numbers = np.ndarray | list[Any]


class Smoothness(TypedDict):
    """Turning angles between consecutive unit tangents (paper eq. 8), in degrees."""

    mean_turn: Annotated[float | None, Field(description="Mean turning angle: how much the curve bends.")]
    max_turn: Annotated[float | None, Field(description="The sharpest corner.")]
    roughness: Annotated[
        float | None,
        Field(
            description="Mean change of turning angle between neighbouring points: near 0 for a smooth curve, "
            "large where tangents jitter."
        ),
    ]


class CurveMetrics(TypedDict):
    """Quality of one returned curve, measured in the frame it is returned in (null: beyond float64)."""

    smoothness: Smoothness
    self_intersects: Annotated[bool, Field(description="Whether the open polyline crosses or touches itself.")]
    length: Annotated[float | None, Field(description="Polyline length, in the curve's own units.")]


class ClosenessOut(TypedDict):
    """How close an answer came to its input, relative to the input's size: 0.001 is 0.1% of its diagonal."""

    rms: Annotated[
        float | None,
        Field(
            description="Root mean squared distance between the input's points and the answer's matched points, ÷ "
            "the input's bounding-box diagonal (null only where float64 overflowed)."
        ),
    ]
    max: Annotated[float | None, Field(description="The largest such distance (the worst point), ÷ the same diagonal.")]
    max_at: Annotated[int, Field(description="Index in the input of that worst point.")]


#: What a frame's fields mean, said once: for the answers' FrameOut and for a request's frame (service.fields).
FRAME_FIELDS = {
    "center": "Bounding-box centre [x, y].",
    "size": "Larger side of the bounding box.",
    "rotation": "Radians, counter-clockwise, the curve was turned by (after `mirror`) to reach the model.",
    "mirror": "Whether it was mirrored (x -> -x about `center`) first.",
    "reverse": "Whether the curve's point order was reversed.",
}


class FrameOut(TypedDict):
    """Where a curve lives: centre of its bounding box and its larger side; and the pose that turned it into the
    model's orientation (pose "auto"). /decode and /reconstruct read it back as a request's `frames`."""

    center: Annotated[Point, Field(description=FRAME_FIELDS["center"])]
    size: Annotated[float, Field(description=FRAME_FIELDS["size"])]
    rotation: Annotated[float, Field(description=FRAME_FIELDS["rotation"])]
    mirror: Annotated[bool, Field(description=FRAME_FIELDS["mirror"])]
    reverse: Annotated[bool, Field(description=FRAME_FIELDS["reverse"])]


class ClampedSpline(TypedDict):
    """A clamped cubic B-spline: what every spline of a body holds."""

    control_points: Annotated[list[Point], Field(description="n_ctrl control points [x, y].")]
    knots: Annotated[
        list[float], Field(description="Clamped uniform knot vector on [0, 1], n_ctrl + degree + 1 entries.")
    ]
    degree: Annotated[int, Field(description="3: cubic.")]


class SplineOut(ClampedSpline):
    """A returned curve as a clamped cubic B-spline, in the frame the curve is returned in."""

    params: Annotated[
        list[float], Field(description="The spline parameter in [0, 1] of each point of the returned curve, in order.")
    ]


class EncodeResponse(TypedDict):
    mean: Annotated[
        Numbers, NumpyJson(list[list[float]]), Field(description="Latent mean of each curve (batch × latent_dim).")
    ]
    log_var: Annotated[
        Numbers,
        NumpyJson(list[list[float]]),
        Field(description="Latent log-variance of each curve (batch × latent_dim)."),
    ]
    frames: Annotated[
        list[FrameOut] | None,
        Field(
            description='The frame each curve was mapped from (frame "auto"); pass them to /decode to map back. '
            'null for frame "model".'
        ),
    ]
    closeness: NotRequired[
        Annotated[
            list[ClosenessOut],
            Field(
                description="Per curve, where the reading decoded the latent (the shipped model's closest placement): "
                "how close its decoding comes to the curve, relative to its size (as /reconstruct)."
            ),
        ]
    ]


class CurvesResponse(TypedDict):
    curves: NotRequired[
        Annotated[
            Numbers,
            NumpyJson(list[list[Point]]),
            Field(description='Curves as arrays of [x, y] points (output "points" or "both").'),
        ]
    ]
    splines: NotRequired[
        Annotated[
            list[SplineOut],
            Field(description='The same curves as B-splines, one per curve (output "bspline" or "both").'),
        ]
    ]
    metrics: NotRequired[
        Annotated[
            list[CurveMetrics],
            Field(
                description="One entry per returned curve, in order; present only when the request asks for `metrics`."
            ),
        ]
    ]


class ReconstructResponse(CurvesResponse):
    mse: Annotated[
        Numbers,
        NumpyJson(list[float]),
        Field(
            description="Per curve: mean squared error over points and coordinates (paper eq. 4) between the input "
            "and its reconstruction at the input's own points, in the caller's frame: each input point against the "
            "returned point matched to it (with the shipped model's closest placement, its closest point on the "
            "reconstruction; GET /model: spline.placement)."
        ),
    ]
    closeness: Annotated[
        list[ClosenessOut],
        Field(
            description="Per curve: how close the reconstruction came relative to the input's size (its RMS and "
            "largest distance ÷ the input's bounding-box diagonal, and where the largest is): unitless, unlike `mse`."
        ),
    ]
    repaired: Annotated[
        list[bool],
        Field(
            description="Per curve: whether the decoded curve crossed itself where the input does not and its spline "
            "was refitted to the input around the crossing (a valid shape, as close or closer; the returned latent, "
            "from /encode, decodes to the curve before). Answers never cross themselves where their inputs do not."
        ),
    ]


class InterpolateResponse(CurvesResponse):
    weights: Annotated[
        Numbers,
        NumpyJson(list[list[float]]),
        Field(description="The weight row of each returned curve, one entry per input curve."),
    ]
    frames: Annotated[
        list[FrameOut] | None,
        Field(description='Frame "auto": the blend of the inputs\' frames each interpolant was mapped into.'),
    ]
    valid: Annotated[
        list[bool],
        Field(
            description="Per returned curve: free of self-crossings. An in-between that crossed itself is refitted "
            "near the crossing to the blend of its ends' answers; false where even that crosses (the ends cannot be "
            "joined there by valid curves)."
        ),
    ]
    repaired: Annotated[list[bool], Field(description="Per returned curve: whether it was refitted near a crossing.")]
    ends: Annotated[
        list[ClosenessOut],
        Field(
            description="Per input curve: how close its own reconstruction in the set's reading (the sweep's end) "
            "came, relative to its size; empty for a model that decodes only the mixes."
        ),
    ]


class SampleResponse(CurvesResponse):
    latents: Annotated[list[list[float]], Field(description="The latent vector each curve was decoded from.")]
    seed: Annotated[int, Field(description="The seed used: the request's, or the one drawn for it.")]
    offset: Annotated[int, Field(description="Index of the first returned curve in the seeded sequence.")]
    prior: Annotated[
        str, Field(description="The distribution the latents were drawn from: learned, standard or a named prior.")
    ]
    rejected: Annotated[
        int, Field(description="Draws rejected (self-intersecting or outside the disc) and drawn again.")
    ]
    invalid: Annotated[
        int, Field(description="Curves still invalid after 10 draws each (returned as drawn; normally 0).")
    ]
    frames: NotRequired[
        Annotated[
            list[FrameOut] | None,
            Field(
                description="With a prior fitted to users' curves: the frame each curve came back in (its nearest "
                "reference curve's: their position, size and orientation)."
            ),
        ]
    ]


class DirectionOut(TypedDict):
    deviation: Annotated[
        float, Field(description="The distribution's standard deviation along the direction, in latent units.")
    ]
    share: Annotated[float, Field(description="The direction's share of the distribution's total variance.")]


class ExploreResponse(CurvesResponse):
    offsets: Annotated[
        list[list[float]],
        Field(
            description="Per curve: its offset along each direction, in standard deviations (the last direction "
            "varies fastest: for two, row by row of the grid)."
        ),
    ]
    valid: Annotated[list[bool], Field(description="Per curve: false where it crosses itself.")]
    directions: Annotated[
        list[DirectionOut], Field(description="The principal directions followed, the largest first.")
    ]
    prior: Annotated[
        str,
        Field(description="The distribution whose directions they are: learned, standard or a named prior."),
    ]


class AugmentResponse(CurvesResponse):
    sources: Annotated[
        list[list[int]],
        Field(description="Indices into the request's `curves` of each new curve's sources: its anchor first."),
    ]
    weights: Annotated[
        list[list[float]],
        Field(description="Weight of each source, in the order of `sources`: each ≥ 0, each row summing to 1."),
    ]
    frames: Annotated[list[FrameOut] | None, Field(description='Frame "auto": the blend of the sources\' frames.')]
    seed: Annotated[
        int, Field(description="The seed used: the request's, or the one drawn for it (to repeat or page on).")
    ]
    offset: Annotated[int, Field(description="Index of the first returned curve in the seeded sequence.")]
    redrawn: Annotated[
        int,
        Field(
            description="Mixes that crossed themselves and were drawn again, from their item's own seeded generator."
        ),
    ]
    invalid: Annotated[int, Field(description="Curves still crossing themselves after 10 draws each (normally 0).")]


class BSplineOut(ClampedSpline):
    n_ctrl: Annotated[int, Field(description="Number of control points (given, or chosen by the tolerance).")]
    rms_error: Annotated[
        float, Field(description="Root mean squared distance of the points from the spline at their parameter.")
    ]
    max_error: Annotated[float, Field(description="Largest such distance.")]
    curve: NotRequired[Annotated[list[Point], Field(description="The spline at `n_points`, when asked for.")]]


class FitResponse(TypedDict):
    fits: Annotated[list[BSplineOut], Field(description="One fit per input curve, in order.")]
