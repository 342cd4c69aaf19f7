"""`curve-vae train` and `average`: training runs (training/train.py), checkpoint averages (training/average.py)."""

from __future__ import annotations

import argparse
import os
from dataclasses import fields
from pathlib import Path

from curve_vae.commands.options import (
    DATA_HELP,
    add_data_options,
    data_config,
    data_path,
)
from curve_vae.files import refuse_overwrite
from curve_vae.progress import shown

#: Each TrainConfig field's help text (its default is added from the config).
TRAIN_HELP = {
    "epochs": "epochs (passes over the training curves)",
    "batch_size": "global batch size, split across DDP processes",
    "lr": "Adam learning rate; the peak rate of the onecycle schedule",
    "schedule": "learning-rate schedule: {schedules}",
    "warmup": "onecycle: fraction of the steps spent warming up",
    "beta": "weight of the KL term",
    "lap_weight": "weight of the Laplacian smoothness term (0: off)",
    "grad_clip": "clip the gradient norm to this (0: off)",
    "patience": "early stopping: epochs without a better validation MSE (0: off)",
    "bf16": "bf16 autocast (fast only with AMX/AVX512-BF16 CPUs or GPUs)",
    "compile": "torch.compile the model",
    "seed": "seed of initialisation, batch order and sampling noise",
    "threads": "torch CPU threads (0: torch's default)",
    "device": "auto | cpu | cuda",
    "train_limit": "use only the first N training curves (0: all)",
    "time_budget": "seconds of training; the schedule follows elapsed training time and the run "
    "stops when it is spent, whatever the throughput (0: off; --epochs stays an upper bound)",
    "snapshots": "keep the weights of the latest N epochs as RUN_DIR/epoch-NNNN.pt, to average them "
    "afterwards with curve-vae average (0: off)",
    "only_params": "with --spline-params: train only where the points sit along the curves (the head's "
    "parameter channel); every other weight and BatchNorm statistic stays the starting model's",
    "match": "what the reconstruction error measures: index (eq. 4, point i to point i); closest (each "
    "point to its closest point on the decoded spline and back, whatever the points' spacing; needs the "
    "B-spline head; validation and model selection measure it too); twin (eq. 4 against the curve drawn "
    "evenly in its own parameter); mixed (index for curves drawn at their own spacing, closest for the rest)",
    "only_encoder": "train only the encoder: the decoder's weights and every BatchNorm statistic stay the "
    "starting model's, so every latent decodes as before and only which latent a curve gets changes",
}


def add_train_options(p: argparse.ArgumentParser) -> None:
    _add_model_options(p)
    _add_training_options(p)


def _add_model_options(p: argparse.ArgumentParser) -> None:
    """The network's options (paper §3.5): variant, latent size, the B-spline head."""
    from curve_vae.training.config import VARIANTS

    g = p.add_argument_group("model (paper §3.5)")
    g.add_argument(
        "--variant",
        default="inception",
        help=f"architecture: {', '.join(VARIANTS)} "
        "(cnn6 = inception, the paper's model; cnn1…cnn5: Table 1's ablations) (default: inception)",
    )
    g.add_argument("--latent-dim", type=int, default=32, help="latent size, paper Table 2 (default: 32)")
    g.add_argument(
        "--spline-ctrl",
        type=int,
        default=None,
        help="B-spline output head: project decoded points onto a clamped cubic B-spline with this many "
        "control points, 7k+3 to keep the data's knots (0: raw points) (default: the --init-from or resumed "
        "checkpoint's head, else 0)",
    )
    g.add_argument(
        "--spline-params",
        action=argparse.BooleanOptionalAction,
        default=None,
        help="with the B-spline head: the decoder places each point at a spline parameter of its own (learned; "
        "a model without them continues with the even parameters it had) (default: the --init-from or resumed "
        "checkpoint's, else off)",
    )


def _add_training_options(p: argparse.ArgumentParser) -> None:
    """One flag per TrainConfig field, its default the config's."""
    from curve_vae.training.config import SCHEDULES, TrainConfig

    d = TrainConfig()
    g = p.add_argument_group("training")
    for f in fields(TrainConfig):
        flag = "--" + f.name.replace("_", "-")
        default = getattr(d, f.name)
        help_ = TRAIN_HELP[f.name].format(schedules=" | ".join(SCHEDULES)) + f" (default: {default})"
        if isinstance(default, bool):
            g.add_argument(flag, action=argparse.BooleanOptionalAction, default=default, help=help_)
        else:
            g.add_argument(flag, type=type(default), default=default, help=help_)


def cmd_train(a: argparse.Namespace) -> int:

    from curve_vae.training.config import ModelConfig, TrainConfig
    from curve_vae.training.evaluate import run_evaluation, torch_codec
    from curve_vae.training.figures import plot_training
    from curve_vae.training.train import train

    # keep the head of the weights a run continues from: dropping it would go unnoticed
    start = Path(a.run_dir) / "last.pt" if a.resume and (Path(a.run_dir) / "last.pt").exists() else a.init_from
    started = ModelConfig()
    if start and (a.spline_ctrl is None or a.spline_params is None):
        from curve_vae.training.checkpoint import load_weights

        started = load_weights(start)[0]
    model_cfg = ModelConfig(
        variant=a.variant,
        latent_dim=a.latent_dim,
        spline_ctrl=started.spline_ctrl if a.spline_ctrl is None else a.spline_ctrl,
        spline_params=started.spline_params if a.spline_params is None else a.spline_params,
    )
    cfg = TrainConfig(**{f.name: getattr(a, f.name) for f in fields(TrainConfig)})
    run_dir = Path(a.run_dir)
    state = train(
        run_dir,
        model_cfg,
        data_config(a),
        cfg,
        data_cache=data_path(a, data_config(a)),
        data_workers=a.workers,
        resume=a.resume,
        progress=shown(a.no_progress),
        stop_after=a.stop_after,
        init_from=a.init_from or None,
    )
    if int(os.environ.get("RANK", "0")) != 0:
        return 0
    print(f"best validation MSE {state.best_val:.4f} at epoch {state.best_epoch}; checkpoints in {run_dir}")
    finished = (
        state.epoch >= cfg.epochs
        or (cfg.patience and state.epoch - state.best_epoch >= cfg.patience)
        or 0 < cfg.time_budget <= state.trained_seconds
    )
    if finished:
        from curve_vae.training.data import load_or_generate

        ds = load_or_generate(data_config(a), data_path(a, data_config(a)))
        enc, dec, _ = torch_codec(run_dir / "best.pt")
        report = run_evaluation(
            enc, dec, {"test": ds.test}, run_dir, log_path=run_dir / "log.jsonl", figures=not a.no_figures
        )
        figures = "" if a.no_figures else f", figures {run_dir}/*.png"
        mse = report["test_sets"]["test"]["mse"]
        print(f"test MSE (paper eq. 4) {mse:.4f}; report {run_dir / 'report.json'}{figures}")
    elif (run_dir / "log.jsonl").exists() and not a.no_figures:
        plot_training(run_dir / "log.jsonl", run_dir / "training.png")
    return 0


def cmd_average(a: argparse.Namespace) -> int:
    import torch

    from curve_vae.training.average import average_checkpoints
    from curve_vae.training.checkpoint import atomic_save, load_checkpoint
    from curve_vae.training.data import DataConfig, load_or_generate

    if a.threads > 0:
        torch.set_num_threads(a.threads)
    for p in a.checkpoints:
        if not Path(p).is_file():
            raise SystemExit(f"curve-vae average: no checkpoint at {p}")
    refuse_overwrite(a.out, a.force, "--out")
    d = load_checkpoint(a.checkpoints[-1])["data_config"]
    data_cfg = DataConfig(**{**d, "center": tuple(d["center"])})
    ds = load_or_generate(data_cfg, data_path(a, data_cfg))
    train_curves = ds.train[: a.bn_curves] if a.bn_curves > 0 else None
    ckpt = average_checkpoints(a.checkpoints, train_curves=train_curves, val_curves=ds.val)
    atomic_save(ckpt, Path(a.out))
    print(f"averaged {len(a.checkpoints)} checkpoints → {a.out} (export it with curve-vae export --checkpoint)")
    return 0


def register(sub: argparse._SubParsersAction) -> None:
    s = sub.add_parser("train", help="train a VAE (resumable; DDP under torchrun)")
    s.add_argument(
        "--run-dir", default="runs/default", help="checkpoints, log and report go here (default: runs/default)"
    )
    s.add_argument("--resume", action="store_true", help="continue from RUN_DIR/last.pt if it exists")
    s.add_argument(
        "--stop-after",
        type=int,
        default=0,
        help="stop after this many epochs of this call; resume later (default: 0 = run to --epochs)",
    )
    s.add_argument(
        "--no-progress",
        action="store_true",
        help="no progress bar (none either when stderr is not a terminal); one line per epoch",
    )
    s.add_argument(
        "--no-figures",
        action="store_true",
        help="write the report without its figures (training.png, reconstructions and interpolations: seconds)",
    )
    s.add_argument(
        "--init-from",
        default="",
        help="start a new run from these weights (a checkpoint, or models/vae.pt to continue the shipped model)",
    )
    add_data_options(s)
    add_train_options(s)
    s.set_defaults(func=cmd_train)

    s = sub.add_parser(
        "average", help="average the weights of checkpoints and re-measure BatchNorm statistics (SWA-style)"
    )
    s.add_argument("checkpoints", nargs="+", help="training checkpoints of one run (e.g. best.pt last.pt)")
    s.add_argument("--out", required=True, help="the averaged checkpoint (training format, for export)")
    s.add_argument(
        "--data", default=None, help=f"data set cache of the checkpoints' data config (default: {DATA_HELP})"
    )
    s.add_argument(
        "--bn-curves",
        type=int,
        default=20_000,
        help="training curves to measure BatchNorm statistics on; 0 keeps the averaged ones (default: 20000)",
    )
    s.add_argument("--threads", type=int, default=0, help="torch threads (0: torch's default)")
    s.set_defaults(func=cmd_average)
