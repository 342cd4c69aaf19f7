"""Response bodies of the v1 REST API, with the field docs the OpenAPI page shows (requests: service.schemas)."""

from __future__ import annotations

from typing import Annotated, Any

from pydantic import BaseModel, Field

from curve_vae.inference.choices import Providers
from curve_vae.service.schemas import FrameInfo


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


class ClosenessOut(BaseModel):
    """How close an answer came to its input, relative to the input's size: 0.001 is 0.1% of its diagonal."""

    rms: float | None = Field(
        description="Root mean squared distance between the input's points and the answer's matched points, ÷ the "
        "input's bounding-box diagonal (null only where float64 overflowed)."
    )
    max: float | None = Field(description="The largest such distance (the worst point), ÷ the same diagonal.")
    max_at: int = Field(description="Index in the input of that worst point.")


class EncodeResponse(BaseModel):
    mean: list[list[float]] = Field(description="Latent mean of each curve (batch × latent_dim).")
    log_var: list[list[float]] = Field(description="Latent log-variance of each curve (batch × latent_dim).")
    closeness: list[ClosenessOut] | None = Field(
        None,
        description="Per curve, where the reading decoded the latent (the shipped model's closest placement): how "
        "close its decoding comes to the curve, relative to its size (as /reconstruct).",
    )
    frames: list[FrameInfo] | None = Field(
        description='The frame each curve was mapped from (frame "auto"); pass them to /decode to map back. '
        'null for frame "model".'
    )


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


class ReconstructResponse(CurvesResponse):
    mse: list[float] = Field(
        description="Per curve: mean squared error over points and coordinates (paper eq. 4) between the input and "
        "its reconstruction at the input's own points, in the caller's frame: each input point against the returned "
        "point matched to it (with the shipped model's closest placement, its closest point on the reconstruction; "
        "GET /model: spline.placement)."
    )
    closeness: list[ClosenessOut] = Field(
        description="Per curve: how close the reconstruction came relative to the input's size (its RMS and largest "
        "distance ÷ the input's bounding-box diagonal, and where the largest is): unitless, unlike `mse`."
    )
    repaired: list[bool] = Field(
        description="Per curve: whether the decoded curve crossed itself where the input does not and its spline was "
        "refitted to the input around the crossing (a valid shape, as close or closer; the returned latent, from "
        "/encode, decodes to the curve before). Answers never cross themselves where their inputs do not."
    )


class InterpolateResponse(CurvesResponse):
    weights: list[list[float]] = Field(description="The weight row of each returned curve, one entry per input curve.")
    frames: list[FrameInfo] | None = Field(
        description='Frame "auto": the blend of the inputs\' frames each interpolant was mapped into.'
    )
    valid: list[bool] = Field(
        description="Per returned curve: free of self-crossings. An in-between that crossed itself is refitted near "
        "the crossing to the blend of its ends' answers; false where even that crosses (the ends cannot be joined "
        "there by valid curves)."
    )
    repaired: list[bool] = Field(description="Per returned curve: whether it was refitted near a crossing.")
    ends: list[ClosenessOut] = Field(
        description="Per input curve: how close its own reconstruction in the set's reading (the sweep's end) came, "
        "relative to its size; empty for a model that decodes only the mixes."
    )


class SampleResponse(CurvesResponse):
    latents: list[list[float]] = Field(description="The latent vector each curve was decoded from.")
    seed: int = Field(description="The seed used: the request's, or the one drawn for it.")
    offset: int = Field(0, description="Index of the first returned curve in the seeded sequence.")
    frames: list[FrameInfo] | None = Field(
        None,
        description="With a prior fitted to users' curves: the frame each curve came back in (its nearest "
        "reference curve's: their position, size and orientation).",
    )
    prior: str = Field(description="The distribution the latents were drawn from: learned, standard or a named prior.")
    rejected: int = Field(description="Draws rejected (self-intersecting or outside the disc) and drawn again.")
    invalid: int = Field(description="Curves still invalid after 10 draws each (returned as drawn; normally 0).")


class DirectionOut(BaseModel):
    deviation: float = Field(description="The distribution's standard deviation along the direction, in latent units.")
    share: float = Field(description="The direction's share of the distribution's total variance.")


class ExploreResponse(CurvesResponse):
    offsets: list[list[float]] = Field(
        description="Per curve: its offset along each direction, in standard deviations (the last direction varies "
        "fastest: for two, row by row of the grid)."
    )
    valid: list[bool] = Field(description="Per curve: false where it crosses itself.")
    directions: list[DirectionOut] = Field(description="The principal directions followed, the largest first.")
    prior: str = Field(description="The distribution whose directions they are: learned, standard or a named prior.")


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
    redrawn: int = Field(
        0, description="Mixes that crossed themselves and were drawn again, from their item's own seeded generator."
    )
    invalid: int = Field(0, description="Curves still crossing themselves after 10 draws each (normally 0).")


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


class ErrorItem(BaseModel):
    loc: str = Field(description='Where: field, curve and point, e.g. "curves[2][17][1]".')
    msg: str = Field(description="What is wrong there.")


class ErrorResponse(BaseModel):
    detail: str = Field(description="One line naming the bad field, curve and point, and what is wrong.")
    errors: list[ErrorItem] = Field(default_factory=list, description="Every problem found, first one first.")


class StatusResponse(BaseModel):
    status: str = Field(description='"ok" or "ready"; with a 503: "warming up", "failed" or "stopping"')
    detail: str | None = Field(None, description="what a 503 means and what to do")


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
    reading: dict[str, str | int] = Field(
        description="A request's reading when it sets none of the reading fields: the pose and spacing the model's "
        'encoder was trained for (what "auto" means: "canonical" pose with "parameter" spacing, one encoding per '
        'curve; "search", the candidates searched; "learned" pose, the search\'s candidates ranked by `ranker` and '
        "the first encoded), the looks again after it and the refine steps."
    )
    ranker: dict[str, Any] | None = Field(
        None,
        description='The reading ranker pose "learned" runs, when the model ships one: its file, kind, and how close '
        "its picks came on curves held out of its training (best_of_2: the closer of its first two, ÷ the best of "
        "all the search's candidates).",
    )
    spacer: dict[str, Any] | None = Field(
        None,
        description='The spacing guesser pose "learned" starts its natural fit from, when the model ships one: its '
        "file, kind, and how far its parameters were from the generator's on the paper's curves held out of its "
        "training (mae, rms).",
    )
    cache: dict[str, int] | None = Field(
        None, description="The encoding cache of this worker: entries, bytes held and allowed, hits and misses."
    )
    prior: dict[str, Any] | None = Field(
        None, description="The learned latent distribution /sample draws from by default, when the model ships one."
    )
    priors: dict[str, dict[str, Any]] = Field(
        default_factory=dict,
        description="Priors fitted to users' curves that /sample's `prior` may name (CURVE_VAE_PRIORS_DIR): "
        "components, curves, whether they are closed, the reading they were fitted with.",
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
    requested_providers: Providers
    onnxruntime: str
    metrics: dict[str, Any] | None = Field(None, description="Evaluation results recorded at export, when present.")
    limits: dict[str, int] = Field(description="Request limits of this server.")
    execution: dict[str, Any] = Field(
        description="How this worker runs inference, read back from the live onnxruntime sessions: session pairs, "
        "intra- and inter-op threads, spinning; the threads of numpy's and scipy's BLAS (read back with "
        "threadpoolctl); and the inference threads (slots), micro-batching and coalescing (concurrent requests read "
        "as one batch: most curves, batches read at once, milliseconds a batch waits for company after one) in use."
    )
