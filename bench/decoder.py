"""Inference speed of the decoder: the full layer stack vs the needed prefix (one run).

    .venv/bin/python bench/decoder.py [--batch 256] [--repeats 10] [--threads 1]

Both paths of training/model.py's Decoder in eval mode on the same weights and latents:
prints ms per batch, the ratio, and the largest difference of their outputs in pixels.
The exported ONNX decoder is the prefix path. Quote the ratio; absolute times drift
with machine load.
"""

from __future__ import annotations

import argparse
import time

import torch

from curve_vae.training.model import VAE, ModelConfig


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--variant", default="inception")
    p.add_argument("--batch", type=int, default=256)
    p.add_argument("--repeats", type=int, default=10)
    p.add_argument("--threads", type=int, default=1)
    a = p.parse_args()
    torch.set_num_threads(a.threads)
    torch.manual_seed(0)
    decoder = VAE(ModelConfig(variant=a.variant)).decoder.eval()
    z = torch.randn(a.batch, decoder.cfg.latent_dim)
    ms = {}
    with torch.no_grad():
        outputs = {full: decoder(z, full=full) for full in (True, False)}  # also warms up
        for full in (True, False, True, False):
            t0 = time.perf_counter()
            for _ in range(a.repeats):
                decoder(z, full=full)
            ms[full] = min(ms.get(full, float("inf")), (time.perf_counter() - t0) / a.repeats * 1e3)
    diff = (outputs[True] - outputs[False]).abs().max().item()
    print(f"{a.variant}, batch {a.batch}, {a.threads} thread(s):")
    print(f"  full stack {ms[True]:.1f} ms, prefix {ms[False]:.1f} ms: {ms[True] / ms[False]:.2f}× faster")
    print(f"  largest output difference {diff:.2e} px")


if __name__ == "__main__":
    main()
