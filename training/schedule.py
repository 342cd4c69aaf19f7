"""Learning-rate schedules of a run, by step or by training time: the clock of a time budget and the schedule's
shape (one-cycle, cosine, constant, plateau); the bars that show a run's progress by either."""

from __future__ import annotations

import math
import time
from contextlib import AbstractContextManager, nullcontext

import torch
from tqdm import tqdm

from curve_vae.training.config import TrainConfig


class Clock:
    """Training time spent so far (across resumes) and the fraction of a time budget it is."""

    def __init__(self, budget: float, spent: float) -> None:
        self.budget, self.spent, self._since = budget, spent, 0.0

    def __enter__(self) -> Clock:
        self._since = time.perf_counter()
        return self

    def __exit__(self, *exc: object) -> None:
        self.spent = self.elapsed()
        self._since = 0.0

    def elapsed(self) -> float:
        return self.spent + (time.perf_counter() - self._since if self._since else 0.0)

    def progress(self) -> float:
        return min(1.0, self.elapsed() / self.budget) if self.budget > 0 else 0.0

    def over(self) -> bool:
        return self.budget > 0 and self.elapsed() >= self.budget


def schedule_factor(schedule: str, progress: float, warmup: float) -> float:
    """Learning-rate multiplier at a fraction of the run, the shape of torch's OneCycleLR/cosine."""
    if schedule == "onecycle":
        start, end = 1 / 25, 1 / 25 / 1e3
        if progress < warmup:
            return start + (1 - start) * (1 - math.cos(math.pi * progress / warmup)) / 2
        q = (progress - warmup) / max(1e-12, 1 - warmup)
        return end + (1 - end) * (1 + math.cos(math.pi * q)) / 2
    if schedule == "cosine":
        return 1e-3 + (1 - 1e-3) * (1 + math.cos(math.pi * progress)) / 2
    return 1.0


def make_schedule(opt: torch.optim.Optimizer, cfg: TrainConfig, steps_per_epoch: int, clock: Clock):
    if cfg.time_budget > 0:  # the schedule's clock is training time, whatever the throughput
        for g in opt.param_groups:
            g["initial_lr"] = cfg.lr
        return torch.optim.lr_scheduler.LambdaLR(
            opt, lambda _step: schedule_factor(cfg.schedule, clock.progress(), cfg.warmup)
        )
    total = cfg.epochs * steps_per_epoch
    if cfg.schedule == "onecycle":
        return torch.optim.lr_scheduler.OneCycleLR(
            opt,
            max_lr=cfg.lr,
            total_steps=total,
            pct_start=cfg.warmup,
            div_factor=25.0,
            final_div_factor=1e3,
        )
    if cfg.schedule == "cosine":
        return torch.optim.lr_scheduler.CosineAnnealingLR(opt, T_max=total, eta_min=cfg.lr * 1e-3)
    if cfg.schedule == "plateau":
        return torch.optim.lr_scheduler.ReduceLROnPlateau(opt, factor=0.5, patience=5)
    return None


def time_budget_bar(budget: float, spent: float, shown: bool) -> tqdm | None:
    """A time-budgeted run ends with its budget, not after an epoch count: its bar shows seconds (None: no budget)."""
    if budget <= 0:
        return None
    return tqdm(
        total=round(budget),
        initial=round(min(spent, budget)),
        desc="time budget",
        unit="s",
        bar_format="{desc}: {percentage:3.0f}%|{bar}| {n:.0f}/{total:.0f} s{postfix}",
        disable=not shown,
        leave=False,
        dynamic_ncols=True,
    )


def epoch_bar(
    epoch: int, epochs: int, n_curves: int, shown: bool, budget_bar: tqdm | None
) -> AbstractContextManager[tqdm]:
    """The coming epoch's bar, closed with the epoch: the run's time-budget bar (left open), or the epoch's curves."""
    if budget_bar is not None:
        return nullcontext(budget_bar)
    return tqdm(
        total=n_curves, desc=f"epoch {epoch}/{epochs}", unit="curve", disable=not shown, leave=False, dynamic_ncols=True
    )
