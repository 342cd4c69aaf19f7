"""Trainer: loop, optimiser, schedule, checkpoints, resume, early stopping, DDP.

Knows nothing about curves beyond "a (N, n_points, 2) float array" (with match "twin" or "mixed", each curve beside its
twin: (N, 2, n_points, 2)): the model owns the architecture, `losses` owns the objectives, which cfg.match
picks. Run under `torchrun --nproc-per-node K` for data-parallel training (gloo on CPU, nccl on GPU); a single
process needs no launcher. Checkpoint files are training/checkpoint.py's.

The schedules, the clock of a time budget and the progress bars are training.schedule's, the process (device, DDP
rank) is training.process'; `train()` reads top to bottom: set-up, then each epoch's pass, validation, record and
stop rules.
"""

from __future__ import annotations

import json
import math
import random
import time
from dataclasses import asdict, dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np
import torch
import torch.distributed as dist
from torch import nn
from tqdm import tqdm

from curve_vae.errors import InvalidInput
from curve_vae.training.checkpoint import (
    CHECKPOINT_VERSION,
    atomic_save,
    check_resumed_data,
    keep_snapshot,
    load_checkpoint,
    load_weights,
    rng_state,
    widen,
)
from curve_vae.training.config import SCHEDULES, TWIN_MATCHES, ModelConfig, TrainConfig
from curve_vae.training.data import DataConfig, load_or_generate
from curve_vae.training.losses import closest_loss, mixed_loss, vae_loss
from curve_vae.training.model import SAMPLES_PER_INTERVAL, VAE
from curve_vae.training.process import Process, agree, autocast, start_process, wrap
from curve_vae.training.schedule import Clock, epoch_bar, make_schedule, schedule_factor, time_budget_bar
from curve_vae.training.validation import validation_measure

__all__ = ["SCHEDULES", "TrainConfig", "schedule_factor", "train", "train_one_epoch"]


@dataclass
class RunState:
    """Everything that changes during a run and must survive a restart."""

    epoch: int = 0  # epochs completed
    best_val: float = math.inf
    best_epoch: int = -1
    trained_seconds: float = 0.0  # time spent in training steps, across resumes
    history: list[dict[str, float]] = field(default_factory=list)


def train_one_epoch(
    model: nn.Module,
    data: torch.Tensor,
    order: torch.Tensor,
    opt: torch.optim.Optimizer,
    sched: Any,
    cfg: TrainConfig,
    device: torch.device,
    *,
    bar: tqdm | None = None,
    clock: Clock | None = None,
) -> dict[str, float]:
    """One pass over `data[order]` in batches; returns the mean of each loss term. Match "twin" or "mixed": data
    (n, 2, N, 2), each curve and its twin (the target of its reconstruction, or which says whether it is at its own
    spacing).

    With a clock on a time budget, the pass ends early once the budget is spent (on every
    DDP process at the same step: rank 0's clock decides).
    """
    model.train(not cfg.only_encoder)  # encoder alone: decode the mean, as the service does; no sampling noise
    sums: dict[str, torch.Tensor] = {}  # summed on the device: no host sync per step
    n_batches = 0
    per_step = cfg.batch_size // max(1, dist.get_world_size() if dist.is_initialized() else 1)
    for i in range(0, len(order) - per_step + 1, per_step):  # drop the ragged last batch
        if clock is not None and clock.budget > 0 and agree(clock.over()):
            break
        x = data[order[i : i + per_step]].to(device, non_blocking=True)
        terms = _batch_terms(model, x, cfg, device)
        opt.zero_grad(set_to_none=True)
        terms["loss"].backward()
        if cfg.grad_clip > 0:
            nn.utils.clip_grad_norm_(model.parameters(), cfg.grad_clip)
        opt.step()
        if sched is not None and cfg.schedule != "plateau":
            sched.step()
        n_batches += 1
        for k, v in terms.items():
            sums[k] = sums[k] + v.detach() if k in sums else v.detach().float()
        if bar is not None:  # a time-budgeted run's bar counts seconds of the budget; an epoch's, curves
            bar.update(min(clock.elapsed(), clock.budget) - bar.n if clock is not None and clock.budget > 0 else len(x))
            if n_batches % 10 == 0:
                bar.set_postfix({k: f"{float(sums[k]) / n_batches:.4g}" for k in ("loss", "mse", "kl", "lap")})
    return {**{k: float(v) / max(1, n_batches) for k, v in sums.items()}, "steps": n_batches}


def _batch_terms(model: nn.Module, x: torch.Tensor, cfg: TrainConfig, device: torch.device) -> dict[str, torch.Tensor]:
    """The loss terms of one batch under cfg.match."""
    if cfg.match == "twin":  # the curve in, its twin (evenly in its own parameter) the target, point by point
        with autocast(device, cfg.bf16):
            pred, mean, log_var = model(x[:, 0])
        return vae_loss(x[:, 1], pred, mean, log_var, beta=cfg.beta, lap_weight=cfg.lap_weight)
    if cfg.match == "mixed":  # index where the curve is its twin (its own spacing), its shape alone elsewhere
        with autocast(device, cfg.bf16):
            curve, mean, log_var = model(x[:, 0], dense=True)
        beta, lap, stride = cfg.beta, cfg.lap_weight, SAMPLES_PER_INTERVAL
        return mixed_loss(x[:, 0], x[:, 1], curve, mean, log_var, beta=beta, lap_weight=lap, stride=stride)
    with autocast(device, cfg.bf16):
        pred, mean, log_var = model(x, dense=cfg.match == "closest")
    if cfg.match == "closest":
        return closest_loss(x, pred, mean, log_var, beta=cfg.beta)
    return vae_loss(x, pred, mean, log_var, beta=cfg.beta, lap_weight=cfg.lap_weight)


def _load_splits(
    proc: Process, data_cfg: DataConfig, cfg: TrainConfig, cache: str | Path | None, workers: int
) -> tuple[torch.Tensor, torch.Tensor]:
    """Training and validation curves as tensors; rank 0 generates or loads (and writes the cache) first."""
    ds = load_or_generate(data_cfg, cache, workers=workers) if proc.rank == 0 else None
    if proc.distributed:
        dist.barrier()
        if proc.rank != 0:
            ds = load_or_generate(data_cfg, cache)
    assert ds is not None
    train_np = ds.train[: cfg.train_limit] if cfg.train_limit else ds.train
    if cfg.match in TWIN_MATCHES:  # each curve with its twin: (n, 2, N, 2)
        if ds.train_twins is None:
            raise InvalidInput(f'match {cfg.match!r} needs a data set with twins (mix "broad", DataConfig.twins)')
        train_np = np.stack([train_np, ds.train_twins[: len(train_np)]], axis=1)
    return torch.from_numpy(np.ascontiguousarray(train_np)), torch.from_numpy(np.ascontiguousarray(ds.val))


@dataclass
class _Parts:
    """What the steps change beside RunState, and a checkpoint keeps: the model, its optimiser and schedule, the
    clock of the time budget (the schedule's, on a budget) and the generator of each epoch's order."""

    model: VAE
    opt: torch.optim.Optimizer
    sched: Any
    clock: Clock
    gen: np.random.Generator


def _new_parts(proc: Process, model_cfg: ModelConfig, cfg: TrainConfig, steps_per_epoch: int) -> _Parts:
    model = VAE(model_cfg).to(proc.device)
    trained = (
        model.learn_only_params()
        if cfg.only_params
        else model.learn_only_encoder()
        if cfg.only_encoder
        else model.parameters()
    )
    opt = torch.optim.Adam(trained, lr=cfg.lr)
    clock = Clock(cfg.time_budget, 0.0)
    return _Parts(model, opt, make_schedule(opt, cfg, steps_per_epoch, clock), clock, np.random.default_rng(cfg.seed))


def _restore(
    proc: Process, last: Path, parts: _Parts, cfg: TrainConfig, *, resume: bool, init_from: str | Path | None
) -> RunState:
    """Resume from `last` (weights, optimiser, schedule, RNG, run state) or start anew, from `init_from`'s weights
    if given; the state the run starts from."""
    model, sched = parts.model, parts.sched
    if resume and last.exists():
        ckpt = load_checkpoint(last)
        was = ckpt["train_config"]["epochs"]
        if sched is not None and cfg.schedule in ("onecycle", "cosine") and was != cfg.epochs:
            raise InvalidInput(
                f"{last} was trained for a {was}-epoch {cfg.schedule} schedule; resume it with --epochs {was}, "
                "or start a new run directory (use --init-from to start from its weights)"
            )
        model.load_state_dict(ckpt["model"])
        parts.opt.load_state_dict(ckpt["optimizer"])
        if sched is not None and ckpt.get("scheduler") is not None:
            sched.load_state_dict(ckpt["scheduler"])
        torch.set_rng_state(ckpt["rng"]["torch"])
        parts.gen.bit_generator.state = json.loads(ckpt["rng"]["numpy"])
        state = RunState(**ckpt["state"])
        proc.say(f"resumed {last} at epoch {state.epoch}/{cfg.epochs}")
        return state
    if resume:
        proc.say(f"no checkpoint at {last}: starting a new run")
    if init_from:
        init_cfg, weights = load_weights(init_from)
        if model.cfg.spline_params and not init_cfg.spline_params and init_cfg.spline_ctrl:
            init_cfg, weights = replace(init_cfg, spline_params=True), widen(weights, model)
        if not init_cfg.same_weights(model.cfg):
            raise InvalidInput(f"{init_from} holds a {asdict(init_cfg)} model, not {asdict(model.cfg)}")
        model.load_state_dict(weights)
        proc.say(f"initialised from {init_from}")
    return RunState()


def _validate(proc: Process, parts: _Parts, val: torch.Tensor, cfg: TrainConfig) -> float:
    """The validation MSE, rank 0's on every process, so that all stop together; a plateau schedule steps on it."""
    val_mse = validation_measure(cfg.match)(parts.model, val, device=proc.device)
    if proc.distributed:
        v = torch.tensor([val_mse], dtype=torch.float64)
        dist.broadcast(v, 0)
        val_mse = float(v)
    if parts.sched is not None and cfg.schedule == "plateau":
        parts.sched.step(val_mse)
    return val_mse


def _record_epoch(run_dir: Path, ckpt: dict[str, Any], row: dict[str, float], improved: bool, cfg: TrainConfig) -> None:
    """Rank 0's files of an epoch: best.pt if it improved, last.pt, the snapshot, the log line; and its line."""
    if improved:
        atomic_save(ckpt, run_dir / "best.pt")
    atomic_save(ckpt, run_dir / "last.pt")
    if cfg.snapshots:
        keep_snapshot(run_dir, ckpt, int(row["epoch"]), cfg.snapshots)
    with open(run_dir / "log.jsonl", "a") as f:
        f.write(json.dumps(row) + "\n")
    print(  # one line per epoch, with or without the progress bar
        f"epoch {row['epoch']}/{cfg.epochs}  loss {row['train_loss']:.4g}  mse {row['train_mse']:.4g}  "
        f"kl {row['train_kl']:.4g}  lap {row['train_lap']:.4g}  val_mse {row['val_mse']:.4g}"
        f"{' *' if improved else ''}  {row['curves_per_s']:.0f} curves/s",
        flush=True,
    )


def _steps_per_epoch(n_curves: int, proc: Process, cfg: TrainConfig) -> int:
    """Full batches per epoch on each process (the ragged last batch is dropped)."""
    steps = n_curves // proc.world // (cfg.batch_size // proc.world)
    if steps < 1:
        raise InvalidInput(f"{n_curves} training curves are fewer than one batch of {cfg.batch_size}")
    return steps


def _write_config(run_dir: Path, configs: dict[str, Any]) -> None:
    run_dir.mkdir(parents=True, exist_ok=True)
    (run_dir / "config.json").write_text(json.dumps(configs, indent=2))


def _epoch_order(gen: np.random.Generator, n_curves: int, proc: Process, per_epoch: int) -> torch.Tensor:
    """This process's share of a fresh permutation (the same on every rank), `per_epoch` curves."""
    perm = torch.from_numpy(gen.permutation(n_curves))
    return perm[proc.rank :: proc.world][:per_epoch]


def _close_epoch(
    state: RunState, parts: _Parts, terms: dict[str, float], val_mse: float, seconds: float, cfg: TrainConfig
) -> tuple[dict[str, float], bool]:
    """Count the epoch into `state` (training time, its history row, the best validation MSE); the row and whether
    it improved."""
    state.epoch += 1
    state.trained_seconds = parts.clock.spent
    steps = terms.pop("steps")
    row = {
        "epoch": state.epoch,
        **{f"train_{k}": v for k, v in terms.items()},
        "val_mse": val_mse,
        "lr": parts.opt.param_groups[0]["lr"],
        "seconds": seconds,
        "curves_per_s": steps * cfg.batch_size / seconds,
        "trained_seconds": state.trained_seconds,
    }
    state.history.append(row)
    improved = val_mse < state.best_val
    if improved:
        state.best_val, state.best_epoch = val_mse, state.epoch
    return row, improved


def _checkpoint(configs: dict[str, Any], parts: _Parts, state: RunState) -> dict[str, Any]:
    """The checkpoint of the run as it stands: its configs, weights, and what a resume needs."""
    return {
        "version": CHECKPOINT_VERSION,
        "model_config": configs["model"],
        "data_config": configs["data"],
        "train_config": configs["train"],
        "model": parts.model.state_dict(),
        "optimizer": parts.opt.state_dict(),
        "scheduler": parts.sched.state_dict() if parts.sched is not None else None,
        "state": asdict(state),
        "rng": rng_state(parts.gen),
    }


def _stop_reason(cfg: TrainConfig, state: RunState, clock: Clock) -> str | None:
    """Why the run stops before its last epoch (patience out, time budget spent), or None. Every process calls it
    and gets rank 0's answer, so all stop at the same epoch."""
    if cfg.patience and state.epoch - state.best_epoch >= cfg.patience:
        return f"early stop: no better validation MSE for {cfg.patience} epochs"
    if agree(clock.over()):
        return f"time budget of {cfg.time_budget:.0f} s spent after {state.epoch} epochs"
    return None


def _check_match(model_cfg: ModelConfig, cfg: TrainConfig) -> None:
    """A loss on the decoded spline needs the B-spline head; "mixed" needs it at even parameters."""
    if cfg.match != "index" and not model_cfg.spline_ctrl:
        raise InvalidInput(
            f"match {cfg.match!r} measures the decoded spline: it needs the B-spline head (--spline-ctrl)"
        )
    if cfg.match == "mixed" and model_cfg.spline_params:
        # its index half measures the decoder's even parameters, which learned parameters would not serve
        raise InvalidInput('match "mixed" needs the B-spline head at even parameters (spline_ctrl, no spline_params)')


def _run_epochs(
    run_dir: Path,
    proc: Any,
    net: Any,
    parts: _Parts,
    state: RunState,
    splits: tuple[Any, Any],
    configs: dict[str, Any],
    cfg: TrainConfig,
    *,
    end: int,
    progress: bool,
) -> None:
    """Epochs until `end` (or patience or the time budget runs out): train, validate, record, checkpoint."""
    data, val = splits
    steps_per_epoch = _steps_per_epoch(len(data), proc, cfg)
    shown = progress and proc.rank == 0
    budget_bar = time_budget_bar(cfg.time_budget, state.trained_seconds, shown)
    while state.epoch < end:
        t0 = time.perf_counter()
        order = _epoch_order(parts.gen, len(data), proc, steps_per_epoch * (cfg.batch_size // proc.world))
        with epoch_bar(state.epoch + 1, cfg.epochs, len(order), shown, budget_bar) as bar, parts.clock as clock:
            terms = train_one_epoch(net, data, order, parts.opt, parts.sched, cfg, proc.device, bar=bar, clock=clock)
        train_time = time.perf_counter() - t0
        val_mse = _validate(proc, parts, val, cfg)
        row, improved = _close_epoch(state, parts, terms, val_mse, train_time, cfg)
        if proc.rank == 0:
            _record_epoch(run_dir, _checkpoint(configs, parts, state), row, improved, cfg)
        stop = _stop_reason(cfg, state, parts.clock)
        if stop:
            proc.say(stop)
            break
    if budget_bar is not None:
        budget_bar.close()


def train(
    run_dir: str | Path,
    model_cfg: ModelConfig,
    data_cfg: DataConfig,
    cfg: TrainConfig,
    *,
    data_cache: str | Path | None = None,
    data_workers: int = 1,
    resume: bool = False,
    progress: bool = True,
    stop_after: int = 0,
    init_from: str | Path | None = None,
) -> RunState:
    """Train into `run_dir` (last.pt, best.pt, log.jsonl, epoch-NNNN.pt snapshots); resume from last.pt if asked.

    stop_after: leave after this many epochs of this call (0: run to cfg.epochs), so a long
    schedule can be run in time-boxed slices and continued with resume=True.
    init_from: a new run starts from these weights (a checkpoint or a shipped vae.pt) with a
    fresh optimiser and schedule: fine-tuning, or continuing the shipped model on a new machine.
    """
    run_dir = Path(run_dir)
    _check_match(model_cfg, cfg)
    proc = start_process(cfg)
    try:
        torch.manual_seed(cfg.seed)
        random.seed(cfg.seed)
        check_resumed_data(run_dir / "last.pt", data_cfg, resume)
        data, val = _load_splits(proc, data_cfg, cfg, data_cache, data_workers)
        steps_per_epoch = _steps_per_epoch(len(data), proc, cfg)
        parts = _new_parts(proc, model_cfg, cfg, steps_per_epoch)
        state = _restore(proc, run_dir / "last.pt", parts, cfg, resume=resume, init_from=init_from)
        parts.clock.spent = state.trained_seconds
        net = wrap(proc, parts.model, cfg)  # after the restore: DDP starts every process from rank 0's weights
        configs = {"model": asdict(model_cfg), "data": asdict(data_cfg), "train": asdict(cfg)}
        if proc.rank == 0:
            _write_config(run_dir, configs)

        end = cfg.epochs if not stop_after else min(cfg.epochs, state.epoch + stop_after)
        _run_epochs(run_dir, proc, net, parts, state, (data, val), configs, cfg, end=end, progress=progress)
        return state
    finally:
        if proc.distributed and dist.is_initialized():
            dist.destroy_process_group()
