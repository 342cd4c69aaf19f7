"""Export a trained VAE as two single-file ONNX graphs and a manifest (the service's input).

encoder.onnx: curves (B, n_points, 2) in the 128×128 plane → mean, log_var (B, latent_dim)
decoder.onnx: latent (B, latent_dim) → curves (B, n_points, 2) in the 128×128 plane, and with a
    B-spline head also control_points (B, n_ctrl, 2): curves = basis @ control_points
manifest.json: names, dims, sha256 of each file, the frame convention, config and metrics.
"""

from __future__ import annotations

import json
import logging
import platform
import time
import warnings
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import asdict
from pathlib import Path
from typing import Any

import numpy as np
import torch
from torch import nn

from curve_vae.errors import InvalidInput
from curve_vae.files import atomic_path
from curve_vae.geometry import canonical_frame, clamped_uniform_knots
from curve_vae.inference.choices import SplinePlacement, choices
from curve_vae.inference.generation.prior import PRIOR_FILE, LatentPrior
from curve_vae.inference.model.manifest import (
    DECODER_INPUT,
    ENCODER_INPUT,
    ENCODER_OUTPUTS,
    MANIFEST_VERSION,
    Manifest,
    decoder_outputs,
    file_entry,
)
from curve_vae.training.checkpoint import save_weights
from curve_vae.training.model import VAE, ModelConfig

OPSET = 18


class _EncoderGraph(nn.Module):
    def __init__(self, vae: VAE) -> None:
        super().__init__()
        self.encoder = vae.encoder

    def forward(self, curves: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
        return self.encoder(curves)


class _DecoderGraph(nn.Module):
    """The decoder at inference; with a B-spline head it also returns the control points (and the learned
    parameters of the points, if the head has them)."""

    def __init__(self, vae: VAE) -> None:
        super().__init__()
        self.decoder = vae.decoder

    def forward(self, latent: torch.Tensor) -> torch.Tensor | tuple[torch.Tensor, ...]:
        curves, ctrl, params = self.decoder.decode_params(latent)
        return curves if ctrl is None else (curves, ctrl) if params is None else (curves, ctrl, params)


#: How a consumer places a reconstruction's points (the manifest's spline.placement; inference.choices says what each
#: value does).
PLACEMENTS = choices(SplinePlacement)


def spline_manifest(cfg: ModelConfig, placement: str = "closest") -> dict[str, Any] | None:
    """How the decoder's control points make its curves, for consumers of the graph, and how to place a
    reconstruction's points on them (`PLACEMENTS`)."""
    if not cfg.spline_ctrl:
        return None
    return {
        "n_ctrl": cfg.spline_ctrl,
        "degree": 3,
        "knots": clamped_uniform_knots(cfg.spline_ctrl, 3).tolist(),
        "params": "curve point i is the clamped uniform cubic B-spline at u = params[i], the decoder's output params "
        "(increasing from 0 to 1)"
        if cfg.spline_params
        else f"curve point i is the clamped uniform cubic B-spline at u = i/{cfg.n_points - 1}",
        "output": "control_points",
        **({"learned_params": True} if cfg.spline_params else {}),
        "placement": placement,
    }


@contextmanager
def _quiet_exporter() -> Iterator[None]:
    """Silence what the exporter says that no user can act on: torchvision being absent (its detection ops are not
    used here) and a deprecation inside torch's own pytree code. Real problems still raise."""
    registry = logging.getLogger("torch.onnx._internal.exporter._registration")
    level = registry.level
    registry.setLevel(logging.ERROR)
    try:
        with warnings.catch_warnings():
            warnings.filterwarnings("ignore", message=r".*isinstance\(treespec, LeafSpec\).*", category=FutureWarning)
            yield
    finally:
        registry.setLevel(level)


def export_graph(module: nn.Module, example: torch.Tensor, path: Path, in_name: str, out_names: list[str]) -> None:
    """`module` (in eval mode) as an ONNX graph at `path`, written atomically: one input of `example`'s shape with
    any batch, the outputs named `out_names`."""
    batch = torch.export.Dim("batch", min=1, max=1 << 20)
    module = module.eval()  # inference graphs: BatchNorm on its running statistics
    with atomic_path(path) as tmp, _quiet_exporter():
        program = torch.onnx.export(
            module,
            (example,),
            dynamo=True,
            input_names=[in_name],
            output_names=out_names,
            dynamic_shapes=({0: batch},),
            opset_version=OPSET,
            external_data=False,
            verbose=False,
        )
        assert program is not None, "dynamo=True returns the ONNXProgram"
        program.save(str(tmp), external_data=False)


def model_size_of(curves: np.ndarray) -> float:
    """The bounding-box size (larger side) the model is used to: median over the data set.

    Curves in the caller's frame are scaled to this size before encoding (frame "auto").
    """
    ext = curves.max(axis=1) - curves.min(axis=1)  # (N, 2)
    return float(np.median(ext.max(axis=1)))


def _export_graphs(model: VAE, out: Path) -> list[str]:
    """encoder.onnx and decoder.onnx (with control_points from a B-spline head); their file names."""
    cfg = model.cfg
    export_graph(
        _EncoderGraph(model),
        torch.zeros(2, cfg.n_points, 2) + 64.0,
        out / "encoder.onnx",
        ENCODER_INPUT,
        list(ENCODER_OUTPUTS),
    )
    dec_outputs = decoder_outputs(bool(cfg.spline_ctrl), bool(cfg.spline_params))
    export_graph(_DecoderGraph(model), torch.zeros(2, cfg.latent_dim), out / "decoder.onnx", DECODER_INPUT, dec_outputs)
    return ["encoder.onnx", "decoder.onnx"]


def _graphs_manifest(cfg: ModelConfig) -> dict[str, Any]:
    """The manifest's `graphs`: each graph's file and the shapes of its inputs and outputs."""
    return {
        "encoder": {
            "file": "encoder.onnx",
            "inputs": {"curves": ["batch", cfg.n_points, 2]},
            "outputs": {"mean": ["batch", cfg.latent_dim], "log_var": ["batch", cfg.latent_dim]},
        },
        "decoder": {
            "file": "decoder.onnx",
            "inputs": {"latent": ["batch", cfg.latent_dim]},
            "outputs": {
                "curves": ["batch", cfg.n_points, 2],
                **({"control_points": ["batch", cfg.spline_ctrl, 2]} if cfg.spline_ctrl else {}),
                **({"params": ["batch", cfg.n_points]} if cfg.spline_params else {}),
            },
        },
    }


def _prior_manifest(prior: LatentPrior, prior_info: dict[str, Any] | None) -> dict[str, Any]:
    """The manifest's `prior`: its file, kind, components and how it was fitted."""
    return {"file": PRIOR_FILE, "kind": "gaussian_mixture", "components": len(prior.weights), **(prior_info or {})}


def _frame_manifest(cfg: ModelConfig, model_size: float) -> dict[str, Any]:
    """The manifest's `frame`: the plane the graphs' curves live in and the size the model is used to."""
    return {
        "plane": [128.0, 128.0],
        "center": [cfg.center, cfg.center],
        "model_size": model_size,
        "normalisation": f"inside the graphs: (x - {cfg.center}) / {cfg.scale}; I/O in plane pixels",
        "sampling": f"{cfg.n_points} points evenly spaced in the B-spline parameter",
    }


def export(
    model: VAE,
    out_dir: str | Path,
    *,
    name: str = "curve-vae",
    version: str = "0.0.0",
    model_size: float,
    extra: dict[str, Any] | None = None,
    weights: bool = True,
    prior: LatentPrior | None = None,
    prior_info: dict[str, Any] | None = None,
    placement: str = "closest",
    reading: tuple[str, str] = ("search", "search"),
) -> Manifest:
    """Write encoder.onnx, decoder.onnx, (vae.pt, prior.npz) and manifest.json into out_dir; return the manifest.

    prior: the learned latent distribution (training/prior.py) the service samples from; prior_info
    says how it was fitted. placement: how the service places a reconstruction's points (`PLACEMENTS`).
    reading: the pose and spacing the encoder was trained for (what a request's "auto" means; `reading_of`).
    """
    if placement not in PLACEMENTS:
        raise InvalidInput(f"placement must be one of {', '.join(PLACEMENTS)}, got {placement!r}")
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    model = model.float().cpu().eval()
    cfg = model.cfg
    files = _export_graphs(model, out)
    if prior is not None:
        prior.save(out / PRIOR_FILE)
        files.append(PRIOR_FILE)
    if weights:
        save_weights(model, out / "vae.pt")
        files.append("vae.pt")
    manifest = Manifest.model_validate(
        {
            "manifest_version": MANIFEST_VERSION,
            "name": name,
            "version": version,
            "created": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()),
            "variant": cfg.variant,
            "n_points": cfg.n_points,
            "latent_dim": cfg.latent_dim,
            "files": {f: file_entry(out / f) for f in files},
            "graphs": _graphs_manifest(cfg),
            **({"spline": spline_manifest(cfg, placement)} if cfg.spline_ctrl else {}),
            **({"prior": _prior_manifest(prior, prior_info)} if prior is not None else {}),
            "frame": _frame_manifest(cfg, model_size),
            "reading": {"pose": reading[0], "spacing": reading[1]},
            "model_config": asdict(cfg),
            "opset": OPSET,
            "exported_with": {"torch": torch.__version__, "python": platform.python_version()},
            **(extra or {}),
        }
    )
    manifest.write(out)
    return manifest


# ---------------------------------------------------------------- a training checkpoint into a model directory


def export_checkpoint(
    checkpoint: str | Path,
    out: str | Path,
    *,
    name: str,
    version: str,
    data_cache: str | Path | None = None,
    spline_ctrl: int | None = None,
    placement: str = "closest",
    training_info: str | Path | None = None,
    prior_components: int = 8,
    say: Any = print,
) -> tuple[Manifest, Any, np.ndarray]:
    """Export a training checkpoint (`curve-vae export`): the graphs, the prior (None components: none), the
    manifest with the run's training record; returns the manifest, the data configuration and its test split.

    data_cache: the data set cache of the checkpoint's configuration (default: its default cache file).
    spline_ctrl: the B-spline head to export with in place of the checkpoint's (it has no weights).
    placement: how the service places a reconstruction's points (`PLACEMENTS`; a head's manifest records it).
    training_info: a JSON file merged into the manifest's training section (wall time, hardware, stages).
    """
    from curve_vae.training.checkpoint import load_checkpoint, model_from_checkpoint
    from curve_vae.training.data import DataConfig, default_cache, load_or_generate, load_test_split

    ckpt = load_checkpoint(checkpoint)
    data_cfg = DataConfig(**{**ckpt["data_config"], "center": tuple(ckpt["data_config"]["center"])})
    if data_cfg.mix == "broad":  # posed at one size, tested on the paper's curves: no training split to draw
        from curve_vae.geometry import MODEL_SIZE

        train, test, model_size = None, load_test_split(data_cfg, None), MODEL_SIZE
    else:
        ds = load_or_generate(data_cfg, data_cache or default_cache(data_cfg))
        train, test, model_size = ds.train, ds.test, model_size_of(ds.train)
    model = model_from_checkpoint(checkpoint)
    if spline_ctrl is not None and spline_ctrl != model.cfg.spline_ctrl:
        from dataclasses import replace

        head = VAE(replace(model.cfg, spline_ctrl=spline_ctrl))  # the head has no weights: same state dict
        head.load_state_dict(model.state_dict())
        model = head.eval()
    reading = reading_of(data_cfg)
    prior, prior_info = None, None
    if prior_components:
        prior, count = _fit_shipped_prior(model, data_cfg, train, prior_components, canonical=reading[0] == "canonical")
        prior_info = {"fitted_on": f"latent means of the first {count} training curves of the paper's data set"}
        say(f"fitted a {prior_components}-component latent prior to {count} training curves")
    manifest = export(
        model,
        out,
        name=name,
        version=version,
        model_size=model_size,
        extra={"training": _training_record(ckpt, training_info)},
        prior=prior,
        prior_info=prior_info,
        placement=placement,
        reading=reading,
    )
    return manifest, data_cfg, test


def reading_of(data_cfg: Any) -> tuple[str, str]:
    """The reading a model trained on `data_cfg` expects: one canonical pose and the points as given for the broad mix
    in geometry.canonical_frame's pose (training.families MixSpec.pose), the search for every other."""
    from curve_vae.training.mixes import MIXES

    if data_cfg.mix == "broad" and MIXES[data_cfg.mix_version].pose == "canonical":
        return ("canonical", "parameter")
    return ("search", "search")


def _training_record(ckpt: dict[str, Any], training_info: str | Path | None) -> dict[str, Any]:
    record: dict[str, Any] = {
        "data": ckpt["data_config"],
        "train": ckpt["train_config"],
        "epochs_run": ckpt["state"]["epoch"],
        "best_epoch": ckpt["state"]["best_epoch"],
        "best_val_mse": ckpt["state"]["best_val"],
    }
    if "averaged" in ckpt:  # made by curve-vae average: which checkpoints, and what it measured
        record["averaged"] = ckpt["averaged"]
    if training_info:
        record.update(json.loads(Path(training_info).read_text()))
    return record


def _fit_shipped_prior(
    model: VAE, data_cfg: Any, train: np.ndarray | None, components: int, *, canonical: bool = False
) -> tuple[LatentPrior, int]:
    """The latent prior /sample draws from, fitted to the paper's training curves (with the broad mix too; read in the
    canonical pose for a model that reads curves so), and how many curves it was fitted to."""
    from curve_vae.training.data import generate_curves
    from curve_vae.training.prior import FIT_CURVES, fit_prior

    fit_on = (
        train[:FIT_CURVES]
        if train is not None and data_cfg.mix == "paper"
        else generate_curves(min(FIT_CURVES, data_cfg.n_train), data_cfg.seed, n_points=data_cfg.n_points)[0]
    )
    if canonical:
        from curve_vae.geometry import MODEL_SIZE

        fit_on = np.stack([canonical_frame(c).to_model(c, MODEL_SIZE) for c in fit_on.astype(np.float64)])
        fit_on = fit_on.astype(np.float32)
    with torch.no_grad():
        means = np.concatenate(
            [model.encoder(torch.from_numpy(fit_on[i : i + 500]))[0].numpy() for i in range(0, len(fit_on), 500)]
        )
    return fit_prior(means, components=components), len(fit_on)


def measure_export(
    out: str | Path,
    manifest: Manifest,
    data_cfg: Any,
    test: np.ndarray,
    *,
    fresh_seed: int,
    suite_count: int,
    fresh_count: int = 1000,
) -> dict[str, Any]:
    """Measure the exported graphs as the service runs them (both test sets, the priors' samples, the family
    suite) and store the report in the manifest's `metrics`, written atomically; returns the report."""
    import shutil
    import tempfile

    from curve_vae.inference.runtime import CurveRuntime
    from curve_vae.training.data import generate_curves
    from curve_vae.training.evaluate import run_evaluation, runtime_codec

    fresh, _ = generate_curves(fresh_count, fresh_seed, n_ctrl=data_cfg.n_ctrl, n_points=data_cfg.n_points)
    runtime = CurveRuntime.load(out, providers="cpu")
    enc, dec, _ = runtime_codec(runtime)
    scratch = Path(tempfile.mkdtemp(prefix="curve-vae-export-"))  # run_evaluation's report.json, not kept
    try:
        report = run_evaluation(
            enc,
            dec,
            {"test": test, f"fresh_seed_{fresh_seed}": fresh},
            scratch,
            figures=False,
            runtime=runtime,
            suite_count=suite_count,
        )
    finally:
        shutil.rmtree(scratch, ignore_errors=True)
    manifest.metrics = {"measured_with": "onnxruntime CPU on the exported graphs", **report}
    manifest.write(out)
    return report
