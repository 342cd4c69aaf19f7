"""Where a training process runs: its device, its place among DDP processes (rank 0 alone writes), its threads."""

from __future__ import annotations

import os
from contextlib import nullcontext
from dataclasses import dataclass

import torch
import torch.distributed as dist
from torch import nn

from curve_vae.errors import InvalidInput
from curve_vae.training.config import TrainConfig


def pick_device(name: str) -> torch.device:
    if name == "auto":
        return torch.device("cuda" if torch.cuda.is_available() else "cpu")
    if name == "cuda" and not torch.cuda.is_available():
        raise InvalidInput("--device cuda asked for, but torch sees no CUDA device")
    return torch.device(name)


def autocast(device: torch.device, bf16: bool):
    return torch.autocast(device.type, dtype=torch.bfloat16) if bf16 else nullcontext()


@dataclass
class Process:
    """Where this process trains: its device, and its place among the DDP processes (rank 0 alone writes)."""

    device: torch.device
    rank: int = 0
    world: int = 1

    @property
    def distributed(self) -> bool:
        return self.world > 1

    def say(self, message: str) -> None:
        if self.rank == 0:
            print(message, flush=True)


def start_process(cfg: TrainConfig) -> Process:
    device = pick_device(cfg.device)
    if int(os.environ.get("WORLD_SIZE", "1")) > 1:
        if device.type == "cuda":
            device = torch.device("cuda", int(os.environ.get("LOCAL_RANK", "0")))
            torch.cuda.set_device(device)
        dist.init_process_group("nccl" if device.type == "cuda" else "gloo")
    if cfg.threads > 0:
        torch.set_num_threads(cfg.threads)
    if device.type == "cuda":
        torch.backends.cudnn.benchmark = True  # every batch has the same shape: pick the fastest kernels once
    if dist.is_initialized():
        return Process(device, dist.get_rank(), dist.get_world_size())
    return Process(device)


def agree(flag: bool) -> bool:
    """Rank 0's flag on every process (a no-op without DDP)."""
    if not dist.is_initialized():
        return flag
    t = torch.tensor([int(flag)])
    dist.broadcast(t, 0)
    return bool(t.item())


def wrap(proc: Process, model: nn.Module, cfg: TrainConfig) -> nn.Module:
    """The module the steps run: DDP across processes, compiled if asked."""
    net: nn.Module = model
    if proc.distributed:
        net = nn.parallel.DistributedDataParallel(
            model, device_ids=[proc.device.index] if proc.device.type == "cuda" else None
        )
    # torch.compile of a Module is an OptimizedModule (a Module); its stub says only Callable
    return torch.compile(net) if cfg.compile else net  # type: ignore[return-value]
