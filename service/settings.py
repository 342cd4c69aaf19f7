"""Service configuration: every option is a field here and an environment variable CURVE_VAE_<FIELD>.

`curve-vae serve`'s flags are made from the fields (service.server.configure_parser: each one's description is its
help, its `flag` group its heading) and override the environment; tests build `Settings(...)` directly and
hand it to `create_app`. Nothing is read at import time: `get_settings()` reads the
environment when it is called.
"""

from __future__ import annotations

from functools import lru_cache
from pathlib import Path
from typing import Annotated, Any, Literal

from pydantic import Field, field_validator
from pydantic_settings import BaseSettings, NoDecode, SettingsConfigDict

from curve_vae.inference.choices import Placement, Providers
from curve_vae.inference.model.shipped import SHIPPED, model_directory

#: The `curve-vae serve --help` group of a field with a flag (`json_schema_extra`; service.server.GROUPS): what
#: everyone sets, the limits of one request, tuning. A field without one (API keys, metrics) is set by environment only.
EVERYONE: dict[str, Any] = {"flag": "everyone"}
LIMITS: dict[str, Any] = {"flag": "limits"}
TUNING: dict[str, Any] = {"flag": "tuning"}


class Settings(BaseSettings):
    """Configuration of one service process (every worker reads the same). A field's description is its `serve --help`
    line; a comment above it says what the line has no room for."""

    model_config = SettingsConfigDict(env_prefix="CURVE_VAE_", extra="ignore", frozen=True)

    host: str = Field(
        default="127.0.0.1",
        description="interface to listen on; 0.0.0.0 for every interface",
        json_schema_extra=EVERYONE,
    )
    port: int = Field(
        default=8000, ge=0, le=65535, description="TCP port; 0 picks a free one", json_schema_extra=EVERYONE
    )
    # encoder.onnx, decoder.onnx and manifest.json; or a shipped model's name: "default", "paper"
    # (inference/model/shipped.py)
    model_dir: Path = Field(
        default=SHIPPED,
        description="directory with encoder.onnx, decoder.onnx and manifest.json, or a shipped model's name: default, "
        "paper",
        json_schema_extra=EVERYONE,
    )
    # "cuda" fails at startup where CUDA cannot load; "auto" falls back to CPU
    providers: Providers = Field(
        default="auto",
        description="onnxruntime providers: cpu, cuda (an error where CUDA cannot load) or auto",
        json_schema_extra=EVERYONE,
    )
    # uvicorn worker processes, each with its own ONNX sessions; 0: one per CPU this process may use
    # (inference/model/cpus.py)
    workers: int = Field(
        default=0,
        ge=0,
        description="worker processes, each loading its own ONNX sessions; 0: one per CPU",
        json_schema_extra=EVERYONE,
    )
    log_level: Literal["critical", "error", "warning", "info", "debug", "trace"] = Field(
        default="info", description="uvicorn and service log level", json_schema_extra=EVERYONE
    )
    # uvicorn's line per request: log volume (its CPU cost is within noise, BENCHMARKS)
    access_log: bool = Field(
        default=False, description="true: log a line per request (uvicorn's access log)", json_schema_extra=EVERYONE
    )
    # Origins allowed to call from a browser: a JSON list or comma-separated; empty = CORS off.
    cors_origins: Annotated[list[str], NoDecode] = Field(
        default_factory=list,
        description="comma-separated origins allowed to call from a browser; empty: CORS off",
        json_schema_extra=EVERYONE,
    )
    # Priors fitted to users' curves (`curve-vae prior -o DIR/NAME.npz`), loaded at start: /sample's prior "NAME".
    # One fitted to another model than the one served stops the start with a message naming both.
    priors_dir: Path | None = Field(
        default=None,
        description="directory of priors fitted with `curve-vae prior` (NAME.npz: prior NAME)",
        json_schema_extra=EVERYONE,
    )
    # Bytes the encoding cache may hold (inference/prepared.py): curves posted again — the page's slider, a pipeline's
    # seed curves and retries — skip the encoder; 0 turns it off. ~3.4 KB a curve of 161 points.
    cache_bytes: int = Field(
        default=64 << 20,
        ge=0,
        description="bytes of the encoding cache (curves posted again skip the encoder); 0: off",
        json_schema_extra=EVERYONE,
    )
    # A numba cache compiled at an image's build (`curve-vae warm-up` with NUMBA_CACHE_DIR set to it), copied into
    # NUMBA_CACHE_DIR at start where that holds none: a new container or pod loads the reading's kernels instead of
    # compiling them (docs/DEPLOYMENT.md measures both)
    kernel_cache_seed: Path | None = Field(
        default=None,
        description="a numba cache compiled at build (curve-vae warm-up), copied into an empty NUMBA_CACHE_DIR at "
        "start",
        json_schema_extra=EVERYONE,
    )
    max_curves: int = Field(
        default=256,
        ge=1,
        description="most curves, latents or interpolants per request",
        json_schema_extra=LIMITS,
    )
    max_points: int = Field(
        default=4096, ge=4, description="most points per curve, in and out", json_schema_extra=LIMITS
    )
    max_body_bytes: int = Field(
        default=8 << 20,
        ge=1024,
        description="larger request bodies are answered 413",
        json_schema_extra=LIMITS,
    )
    # curves of one streamed .npy (/augment format npy): ~13 MB per 10k
    max_stream_curves: int = Field(
        default=100_000,
        ge=1,
        description="most curves in one streamed .npy (POST /augment format npy)",
        json_schema_extra=LIMITS,
    )
    # triangles of one /revolve mesh: 50 MB of STL
    max_mesh_triangles: int = Field(
        default=1_000_000,
        ge=1,
        description="most triangles in one POST /revolve mesh",
        json_schema_extra=LIMITS,
    )
    # Fitting work of one request, refine × (input points + 300 per curve) + looks × 80 per curve (service/limits.py
    # check_refine): about 35 s of one CPU core here, under request_timeout; 256 curves of 161 points may take 10
    # steps.
    max_refine_work: int = Field(
        default=1_200_000,
        ge=0,
        description="most refine work in one request: refine × (input points + 300 per curve) + looks × 80 per curve",
        json_schema_extra=LIMITS,
    )
    max_queue: int = Field(
        default=64,
        ge=0,
        description="requests waiting for an inference slot; beyond them 503 with Retry-After",
        json_schema_extra=LIMITS,
    )
    request_timeout: float = Field(
        default=60.0,
        ge=0,
        description="seconds a request may take, queueing included (504); 0: none",
        json_schema_extra=LIMITS,
    )
    # Where a reconstruction's points go: "model", as the model's manifest says (spline.placement: the shipped model
    # "closest", each input point at its closest point on the curve, kept in order); "index", the model's own points
    # (docs/RESULTS.md compares the two); or "closest".
    placement: Placement = Field(
        default="model",
        description="model: as the model's manifest says; closest or index whatever it says",
        json_schema_extra=TUNING,
    )
    # curves per ONNX run: large requests are split to bound memory
    batch_size: int = Field(default=64, ge=1, description="curves per ONNX run", json_schema_extra=TUNING)
    # onnxruntime threads per inference; 0: the CPUs this process may use (cgroup quota, affinity) shared out among
    # workers × inference_concurrency (inference/model/cpus.py): no run spreads over more cores than a container's quota
    intra_op_threads: int = Field(
        default=0,
        ge=0,
        description="onnxruntime threads per inference; 0: the CPU quota shared out",
        json_schema_extra=TUNING,
    )
    # onnxruntime's inter-op pool; the graphs run sequentially; 0: its default
    inter_op_threads: int = Field(
        default=1,
        ge=0,
        description="onnxruntime inter-op threads; 0: onnxruntime's default",
        json_schema_extra=TUNING,
    )
    # onnxruntime threads spin-wait between runs: CPU stolen from the other inferences
    spinning: bool = Field(
        default=False, description="true: onnxruntime threads spin-wait between runs", json_schema_extra=TUNING
    )
    # inferences running at once = threads of the inference executor; 0: cpus ÷ workers, at least 2
    # (inference/model/cpus.py)
    inference_concurrency: int = Field(
        default=0,
        ge=0,
        description="inferences at once; 0: one per CPU of a worker, at least 2",
        json_schema_extra=TUNING,
    )
    sessions: int = Field(
        default=0,
        ge=0,
        description="onnxruntime session pairs per worker; 0: one per inference running at once",
        json_schema_extra=TUNING,
    )
    # Micro-batching (inference/model/batching.py): concurrent requests' graph runs gathered into one run of at most
    # micro_batch_rows rows, waiting at most micro_batch_wait_ms for company. Off: slower on this CPU
    # (docs/BENCHMARKS.md); on a GPU turn it on.
    micro_batch: bool = Field(
        default=False,
        description="true: gather concurrent requests' graph runs into one run",
        json_schema_extra=TUNING,
    )
    micro_batch_rows: int = Field(
        default=32,
        ge=1,
        description="most rows (curves, latents) of one micro-batched run",
        json_schema_extra=TUNING,
    )
    micro_batch_wait_ms: float = Field(
        default=2.0,
        ge=0,
        le=1000,
        description="most milliseconds a run waits for others to join it",
        json_schema_extra=TUNING,
    )
    # Requests that queue for an inference thread at once read as one batch of at most this many curves, each
    # answered its own part (service/deps.py: /encode and /reconstruct of equal options, requests of at most
    # half as many curves; one batch at a time a CPU of the worker); 0: each alone
    coalesce_curves: int = Field(
        default=32,
        ge=0,
        description="most curves of concurrent /encode and /reconstruct requests read as one batch; 0: each alone",
        json_schema_extra=TUNING,
    )
    # milliseconds a thread runs Python before another waiting for the GIL takes it (sys.setswitchinterval, set in
    # each worker at start): the event loop waits less behind the inference threads. At Python's own 5 ms one
    # worker answered 189 single-curve requests a second against 232 (docs/BENCHMARKS.md, service 0.25.0)
    gil_switch_ms: float = Field(
        default=2.0,
        gt=0,
        le=100,
        description="milliseconds a thread runs Python before another takes the GIL (Python's own: 5)",
        json_schema_extra=TUNING,
    )
    # API keys (service/middleware.py), comma-separated or a JSON list; empty = open. Set by environment only,
    # so that keys never show in a process list.
    api_keys: Annotated[list[str], NoDecode] = Field(default_factory=list, repr=False)
    metrics: bool = True  # GET /metrics; false answers 404, to keep the numbers off a public port

    @field_validator("model_dir", mode="before")
    @classmethod
    def _named_model(cls, value: object) -> object:
        return model_directory(value) if isinstance(value, str | Path) else value

    @field_validator("cors_origins", "api_keys", mode="before")
    @classmethod
    def _split_origins(cls, value: object) -> object:
        if isinstance(value, str):
            text = value.strip()
            if text.startswith("["):
                import json

                return json.loads(text)
            return [part.strip() for part in text.split(",") if part.strip()]
        return value


@lru_cache
def get_settings() -> Settings:
    """The process's settings, read from the environment once."""
    return Settings()
