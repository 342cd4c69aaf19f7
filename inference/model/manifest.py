"""The model-file contract: what a model directory's manifest.json says, written by `curve-vae export` and read by
the runtime, the graphs, the Triton writer and GET /model, as one typed `Manifest`.

A model directory holds the two ONNX graphs, a learned prior and the manifest, which lists every file with its
sha256: `Manifest.read(model_dir)` checks all of it and raises `ModelLoadError` with what to fix; nothing is served
that does not match. Fields the manifest carries beyond these (the training record, hardware, …) are kept as they
are. Torch-free.
"""

from __future__ import annotations

import hashlib
import json
import math
from pathlib import Path
from typing import Any

from pydantic import BaseModel, ConfigDict, Field, ValidationError, field_validator

from curve_vae.errors import InvalidInput, ModelError
from curve_vae.files import atomic_write_text
from curve_vae.geometry.frame import MODEL_CENTER
from curve_vae.inference.choices import ModelPose, ModelSpacing, SplinePlacement, choices
from curve_vae.inference.generation.prior import PRIOR_FILE

MANIFEST_VERSION = 1
MANIFEST_FILE = "manifest.json"

#: The graphs' interface, as training/export.py writes it and inference.model.graphs checks it.
ENCODER_INPUT, ENCODER_OUTPUTS = "curves", ("mean", "log_var")  # (B, n_points, 2) -> 2 × (B, latent_dim)
DECODER_INPUT = "latent"  # (B, latent_dim)
DECODER_OUTPUTS = ("curves", "control_points", "params")  # the last two with a B-spline head, learned parameters


def decoder_outputs(splines: bool, params: bool) -> list[str]:
    """The decoder's output names: its curves, then control points (a B-spline head), then each point's parameter."""
    return list(DECODER_OUTPUTS[: 1 + splines + (splines and params)])


class ModelLoadError(ModelError):
    """The model directory or the providers cannot serve: raised at startup, never per request."""


class _Part(BaseModel):
    model_config = ConfigDict(extra="allow")


class FileEntry(_Part):
    sha256: str
    bytes: int = Field(ge=0)


class GraphEntry(_Part):
    file: str
    inputs: dict[str, list[str | int]] = Field(default_factory=dict)
    outputs: dict[str, list[str | int]] = Field(default_factory=dict)


class Graphs(_Part):
    encoder: GraphEntry = GraphEntry(file="encoder.onnx")
    decoder: GraphEntry = GraphEntry(file="decoder.onnx")


class SplineHead(_Part):
    """The decoder's B-spline head: its curves are clamped uniform cubic B-splines with n_ctrl control points."""

    n_ctrl: int = Field(ge=4)
    degree: int = Field(3, ge=1)
    knots: list[float] = Field(default_factory=list)  # reported; the runtime rebuilds them from n_ctrl and degree
    learned_params: bool = False  # a third decoder output places each point at a parameter of its own
    # how a reconstruction's points are placed on the spline; manifests written before placements: "index"
    placement: str = "index"

    @field_validator("placement")
    @classmethod
    def _placement(cls, v: str) -> str:
        if v not in choices(SplinePlacement):
            raise InvalidInput(f"placement must be one of {', '.join(choices(SplinePlacement))}, got {v!r}")
        return v


class PriorEntry(_Part):
    file: str = PRIOR_FILE
    kind: str = "gaussian_mixture"
    components: int | None = None


class RankerEntry(_Part):
    """The reading ranker (inference.ranker): which of the search's candidate readings the model brings back
    closest, predicted from their points, so that only the best two are encoded (reading pose "learned")."""

    file: str = "ranker.onnx"
    kind: str


class SpacerEntry(_Part):
    """The spacing guesser (inference.spacer): where each point of a curve would sit on one of the paper's splines,
    guessed from its shape, so that reading pose "learned" starts its natural fit there."""

    file: str = "spacer.onnx"
    kind: str


class FrameSpec(_Part):
    """The plane the graphs' curves live in (the paper's 128×128, centred on (64, 64)) and the size of a posed
    curve's bounding box there (the training curves' median)."""

    center: tuple[float, float] = MODEL_CENTER
    model_size: float

    @field_validator("model_size")
    @classmethod
    def _finite(cls, v: float) -> float:
        if not (math.isfinite(v) and v > 0):
            raise InvalidInput(f"must be a finite positive size, got {v}")
        return v


class ReadingSpec(_Part):
    """The reading the encoder was trained for: what pose and spacing "auto" mean for this model. Models exported
    before it was recorded read best with the search (six poses, the points as given and their natural readings)."""

    pose: ModelPose = "search"
    spacing: ModelSpacing = "search"


class Manifest(BaseModel):
    """manifest.json of an exported model."""

    model_config = ConfigDict(extra="allow", populate_by_name=True)

    manifest_version: int = MANIFEST_VERSION
    name: str = "curve-vae"
    version: str = "0.0.0"
    created: str | None = None
    variant: str | None = None
    n_points: int = Field(ge=4)
    latent_dim: int = Field(ge=1)
    files: dict[str, FileEntry]
    graphs: Graphs = Graphs()
    spline: SplineHead | None = None
    prior: PriorEntry | None = None
    frame: FrameSpec
    reading: ReadingSpec = ReadingSpec()
    ranker: RankerEntry | None = None
    spacer: SpacerEntry | None = None
    architecture: dict[str, Any] | None = Field(None, alias="model_config")  # the torch ModelConfig, as a dict
    training: dict[str, Any] | None = None
    metrics: dict[str, Any] | None = None

    @field_validator("frame")
    @classmethod
    def _plane(cls, v: FrameSpec) -> FrameSpec:
        if tuple(float(c) for c in v.center) != MODEL_CENTER:  # frames map to this centre (geometry.frame)
            raise InvalidInput(
                f"the model's plane is centred at {list(v.center)}, but curves are mapped to {list(MODEL_CENTER)}; "
                "export the model with the paper's plane (ModelConfig.center 64)"
            )
        return v

    # ------------------------------------------------------------------------------------------ derived values

    @property
    def disc_radius(self) -> float:
        """Radius about the plane's centre the training curves' control points lie in: a valid sample stays in."""
        return float(((self.training or {}).get("data") or {}).get("radius", 64.0))

    def checked_files(self) -> list[str]:
        """The files whose sha256 must match: both graphs, the prior, the ranker and the spacing guesser (never
        vae.pt: serving does not read it)."""
        names = [self.graphs.encoder.file, self.graphs.decoder.file]
        return names + [part.file for part in (self.prior, self.ranker, self.spacer) if part is not None]

    def to_json(self) -> dict[str, Any]:
        """As written to manifest.json (the ModelConfig under its own name, model_config)."""
        return self.model_dump(mode="json", by_alias=True, exclude_none=True)

    # ------------------------------------------------------------------------------------------ files

    @classmethod
    def read(cls, model_dir: str | Path, *, check_files: bool = True) -> Manifest:
        """The manifest of a model directory, checked: fields plausible, and (check_files) every graph and the prior
        present with the sha256 the manifest lists. ModelLoadError says what is wrong and what to do."""
        root = Path(model_dir)
        path = root / MANIFEST_FILE
        if not path.is_file():
            raise ModelLoadError(
                f"no model in {root}: {path.name} is missing (export one with `curve-vae export`, or point "
                "--model-dir / CURVE_VAE_MODEL_DIR at a directory holding encoder.onnx, decoder.onnx and "
                "manifest.json; `--model paper` serves the paper's model shipped with the package)"
            )
        try:
            manifest = cls.model_validate(json.loads(path.read_text()))
        except (ValueError, ValidationError) as e:
            raise ModelLoadError(f"{path}: not a usable manifest ({_reason(e)})") from e
        if check_files:
            manifest.check_files(root)
        return manifest

    def check_files(self, root: Path) -> None:
        for name in self.checked_files():
            file = root / name
            if not file.is_file():
                raise ModelLoadError(f"{file} is missing (listed in {root / MANIFEST_FILE})")
            entry = self.files.get(name)
            if entry is None or not entry.sha256:
                raise ModelLoadError(f"{root / MANIFEST_FILE} carries no sha256 for {name}")
            actual = file_sha256(file)
            if actual != entry.sha256:
                raise ModelLoadError(
                    f"{file}: sha256 {actual} does not match the manifest's {entry.sha256}; "
                    "the file was changed or truncated after export: re-export the model or restore the file"
                )

    def write(self, model_dir: str | Path) -> None:
        """manifest.json into model_dir, atomically."""
        atomic_write_text(Path(model_dir) / MANIFEST_FILE, json.dumps(self.to_json(), indent=2) + "\n")


def file_sha256(path: Path) -> str:
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def file_entry(path: Path) -> FileEntry:
    return FileEntry(sha256=file_sha256(path), bytes=path.stat().st_size)


def _reason(e: Exception) -> str:
    if isinstance(e, ValidationError):
        return "; ".join(f"{'.'.join(str(p) for p in err['loc'])}: {err['msg']}" for err in e.errors())
    return f"{type(e).__name__}: {e}"
