"""Training throughput of a VAE variant on this machine: curves/s per precision mode.

    .venv/bin/python bench/training.py [--variant inception] [--steps 10] [--compile]

Runs full training steps (forward, loss, backward, Adam) on a batch of 128 random curves,
first fp32 then bf16 autocast (and torch.compile if asked), in one process, and prints
curves/s and the ratio to fp32. Absolute numbers drift with machine load; the ratios of
one run are the figure to quote.
"""

from __future__ import annotations

import argparse
import json
import platform
import time

import torch

from curve_vae.training.config import ModelConfig
from curve_vae.training.losses import vae_loss
from curve_vae.training.model import VAE


def measure(model: torch.nn.Module, *, bf16: bool, steps: int, warmup: int, batch: int) -> float:
    opt = torch.optim.Adam(model.parameters(), lr=1e-4)
    x = torch.rand(batch, 161, 2) * 128
    model.train()
    for i in range(warmup + steps):
        if i == warmup:
            t0 = time.perf_counter()
        with torch.autocast("cpu", dtype=torch.bfloat16, enabled=bf16):
            y, mean, log_var = model(x)
        loss = vae_loss(x, y, mean, log_var)["loss"]
        opt.zero_grad()
        loss.backward()
        opt.step()
    return steps * batch / (time.perf_counter() - t0)


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--variant", default="inception", help="model variant (default: inception)")
    p.add_argument("--steps", type=int, default=10, help="timed steps per mode (default: 10)")
    p.add_argument("--batch", type=int, default=128, help="batch size (default: 128)")
    p.add_argument("--compile", action="store_true", help="also time torch.compile (slow to start)")
    a = p.parse_args()
    torch.manual_seed(0)
    modes = [("fp32", False, False), ("bf16", True, False)]
    if a.compile:
        modes.append(("fp32+compile", False, True))
    results = {}
    for name, bf16, comp in modes:
        model = VAE(ModelConfig(variant=a.variant))
        net = torch.compile(model) if comp else model
        results[name] = measure(
            net, bf16=bf16, steps=a.steps if not bf16 else max(2, a.steps // 5), warmup=3 if comp else 1, batch=a.batch
        )
        print(f"{name:>14}: {results[name]:7.1f} curves/s  ({results[name] / results['fp32']:.2f}× fp32)", flush=True)
    print(
        json.dumps(
            {
                "variant": a.variant,
                "threads": torch.get_num_threads(),
                "cpu": platform.processor() or platform.machine(),
                "torch": torch.__version__,
                "curves_per_s": results,
            }
        )
    )


if __name__ == "__main__":
    main()
