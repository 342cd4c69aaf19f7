"""training/schedule.py: a time budget's clock, and the learning-rate schedules by step (torch's) or by training
time (the same shapes as a function of the share of the budget spent); the bars a run shows its progress by."""

from __future__ import annotations

import pytest
import torch

from curve_vae.training import schedule as S
from curve_vae.training.config import TrainConfig


class FakeTime:
    def __init__(self) -> None:
        self.now = 100.0

    def __call__(self) -> float:
        return self.now


@pytest.fixture
def clock_time(monkeypatch) -> FakeTime:
    fake = FakeTime()
    monkeypatch.setattr(S.time, "perf_counter", fake)
    return fake


def test_the_clock_counts_time_inside_its_blocks_on_top_of_what_was_spent(clock_time):
    clock = S.Clock(budget=10.0, spent=4.0)  # 4 s spent before a resume
    assert clock.elapsed() == 4.0 and clock.progress() == pytest.approx(0.4) and not clock.over()
    with clock:
        clock_time.now += 3.0
        assert clock.elapsed() == pytest.approx(7.0)
    clock_time.now += 50.0  # time outside the block (validation, checkpoints) does not count
    assert clock.spent == pytest.approx(7.0) and clock.elapsed() == pytest.approx(7.0)
    with clock:
        clock_time.now += 5.0
        assert clock.over() and clock.progress() == 1.0  # capped at the whole budget
    assert S.Clock(budget=0.0, spent=1e9).progress() == 0.0 and not S.Clock(0.0, 1e9).over()  # no budget


def _torch_factors(cfg: TrainConfig, total: int) -> list[float]:
    """lr / peak lr at steps 0 … total-1 of torch's own scheduler for cfg."""
    opt = torch.optim.SGD([torch.zeros(1, requires_grad=True)], lr=cfg.lr)
    sched = S.make_schedule(opt, cfg, total // cfg.epochs, S.Clock(0.0, 0.0))
    out = []
    for _ in range(total):
        out.append(opt.param_groups[0]["lr"] / cfg.lr)
        opt.step()
        sched.step()
    return out


@pytest.mark.parametrize("schedule", ["onecycle", "cosine"])
def test_a_budgets_schedule_has_the_shape_of_torchs_by_step(schedule):
    total = 200
    cfg = TrainConfig(epochs=4, lr=0.01, schedule=schedule, warmup=0.25)
    by_step = _torch_factors(cfg, total)
    # torch's onecycle reaches its peak at step pct_start·total - 1 and ends at total - 1; cosine spans total steps
    last = total - 1 if schedule == "onecycle" else total
    for step in (0, 10, 49, 80, 150, 199):
        progress = step / last
        if schedule == "onecycle":  # torch's warm-up ends one step early: its phases end at pct·total - 1, total - 1
            peak = cfg.warmup * total - 1
            progress = step / peak * cfg.warmup if step <= peak else cfg.warmup + (step - peak) / (last - peak) * 0.75
        assert S.schedule_factor(schedule, progress, cfg.warmup) == pytest.approx(by_step[step], rel=1e-6, abs=1e-9)


def test_the_shapes_ends():
    assert S.schedule_factor("onecycle", 0.0, 0.1) == pytest.approx(1 / 25)  # div_factor 25
    assert S.schedule_factor("onecycle", 0.1, 0.1) == pytest.approx(1.0)  # the peak after the warm-up
    assert S.schedule_factor("onecycle", 1.0, 0.1) == pytest.approx(1 / 25 / 1e3)  # final_div_factor 1e3
    assert S.schedule_factor("cosine", 0.0, 0.1) == 1.0 and S.schedule_factor("cosine", 1.0, 0.1) == pytest.approx(1e-3)
    assert S.schedule_factor("constant", 0.7, 0.1) == 1.0


def test_on_a_budget_the_rate_follows_the_clock_not_the_steps(clock_time):
    cfg = TrainConfig(lr=0.01, schedule="cosine", time_budget=10.0)
    opt = torch.optim.SGD([torch.zeros(1, requires_grad=True)], lr=cfg.lr)
    clock = S.Clock(cfg.time_budget, 0.0)
    sched = S.make_schedule(opt, cfg, 1000, clock)
    with clock:
        clock_time.now += 5.0  # half the budget, whatever the steps
        opt.step()
        sched.step()
    assert opt.param_groups[0]["lr"] == pytest.approx(0.01 * (1e-3 + (1 - 1e-3) / 2))


@pytest.mark.parametrize(
    "schedule,kind",
    [
        pytest.param("onecycle", torch.optim.lr_scheduler.OneCycleLR, id="onecycle"),
        pytest.param("cosine", torch.optim.lr_scheduler.CosineAnnealingLR, id="cosine"),
        pytest.param("plateau", torch.optim.lr_scheduler.ReduceLROnPlateau, id="plateau"),
        pytest.param("constant", type(None), id="constant-has-none"),
    ],
)
def test_by_step_each_schedule_is_torchs(schedule, kind):
    opt = torch.optim.SGD([torch.zeros(1, requires_grad=True)], lr=0.01)
    assert isinstance(S.make_schedule(opt, TrainConfig(schedule=schedule), 10, S.Clock(0.0, 0.0)), kind)


def test_a_budget_has_a_bar_of_seconds_and_an_epoch_one_of_curves():
    assert S.time_budget_bar(0.0, 0.0, shown=False) is None
    bar = S.time_budget_bar(60.0, 75.0, shown=False)  # more spent than the budget: the bar starts full
    assert bar.total == 60 and bar.n == 60
    with S.epoch_bar(3, 10, 500, False, bar) as same:
        assert same is bar  # the budget's bar, left open across epochs
    bar.close()
    with S.epoch_bar(3, 10, 500, False, None) as own:
        assert own is not bar and own.total == 500
