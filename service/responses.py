"""The bodies the service itself answers, with the field docs the OpenAPI page shows: errors, status and the model's
metadata, each built from its model here. What the model computes is answered in the shapes of inference.answers;
requests are service.schemas'."""

from __future__ import annotations

from typing import Any

from pydantic import BaseModel, Field

from curve_vae.inference.choices import Providers


class ErrorItem(BaseModel):
    loc: str = Field(description='Where: field, curve and point, e.g. "curves[2][17][1]".')
    msg: str = Field(description="What is wrong there.")


class ErrorResponse(BaseModel):
    detail: str = Field(description="One line naming the bad field, curve and point, and what is wrong.")
    errors: list[ErrorItem] = Field(default_factory=list, description="Every problem found, first one first.")


class StatusResponse(BaseModel):
    status: str = Field(description='"ok" or "ready"; with a 503: "warming up", "failed" or "stopping"')
    detail: str | None = Field(default=None, description="what a 503 means and what to do")


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
