"""training/process.py: where a training process runs. Its device as asked (CUDA refused when torch sees none), a
single process without a launcher (rank 0 of 1, which alone speaks), and the module its steps run."""

from __future__ import annotations

import pytest
import torch
from torch import nn

from curve_vae.errors import InvalidInput
from curve_vae.training import process as P
from curve_vae.training.config import TrainConfig


@pytest.mark.parametrize(
    "cuda,name,device",
    [
        pytest.param(False, "auto", "cpu", id="auto-without-cuda"),
        pytest.param(True, "auto", "cuda", id="auto-with-cuda"),
        pytest.param(True, "cpu", "cpu", id="cpu-when-asked"),
    ],
)
def test_the_device_is_the_one_asked_or_cuda_when_there_is_one(monkeypatch, cuda, name, device):
    monkeypatch.setattr(torch.cuda, "is_available", lambda: cuda)
    assert P.pick_device(name) == torch.device(device)


def test_cuda_asked_for_without_a_cuda_device_is_refused(monkeypatch):
    monkeypatch.setattr(torch.cuda, "is_available", lambda: False)
    with pytest.raises(InvalidInput, match="--device cuda asked for, but torch sees no CUDA device"):
        P.pick_device("cuda")


def test_a_process_without_a_launcher_is_rank_0_of_1_and_sets_its_threads(monkeypatch):
    monkeypatch.delenv("WORLD_SIZE", raising=False)
    threads = torch.get_num_threads()
    try:
        proc = P.start_process(TrainConfig(device="cpu", threads=1))
        assert (proc.device, proc.rank, proc.world, proc.distributed) == (torch.device("cpu"), 0, 1, False)
        assert torch.get_num_threads() == 1
    finally:
        torch.set_num_threads(threads)


@pytest.mark.parametrize(
    "rank,said", [pytest.param(0, "hello\n", id="rank-0-speaks"), pytest.param(1, "", id="rank-1")]
)
def test_only_rank_0_speaks(capsys, rank, said):
    P.Process(torch.device("cpu"), rank=rank, world=2).say("hello")
    assert capsys.readouterr().out == said


def test_without_ddp_every_flag_is_its_own_and_the_module_is_the_model():
    assert P.agree(True) is True and P.agree(False) is False
    model = nn.Linear(2, 2)
    assert P.wrap(P.Process(torch.device("cpu")), model, TrainConfig()) is model


def test_autocast_is_bf16_only_when_asked():
    x = torch.ones(2, 2)
    with P.autocast(torch.device("cpu"), bf16=True):
        assert (x @ x).dtype == torch.bfloat16
    with P.autocast(torch.device("cpu"), bf16=False):
        assert (x @ x).dtype == torch.float32
