"""Train the same run twice, decoder over its full length vs over the needed prefix only.

    .venv/bin/python scripts/decoder_prefix_ab.py --variant inception --epochs 2 --train-limit 5000

The decoder's layers produce 518 positions of which 161 are kept (training/model.py,
Decoder). Feeding each layer only the prefix it needs is exact at inference, which is
what the decoder does there; in training BatchNorm's batch statistics would then cover
only the kept positions, so training runs the full stack. This script measures what the
prefix would do to training: identical seeds, data and schedule, one run per
mode (`--mode full|prefix`, or `both` in turn), and prints validation MSE per epoch and
throughput. Runs land in runs/decoder-ab/<variant>-<mode>/.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from curve_vae.cli import main as cli
from curve_vae.training.model import Decoder


def run(mode: str, a: argparse.Namespace) -> list[dict]:
    forward = Decoder.forward
    Decoder.forward = lambda self, z, full=(mode == "full"): forward(self, z, full=full)  # type: ignore[method-assign]
    out = Path(a.out) / f"{a.variant}-{mode}"
    try:
        cli(
            ["train", "--run-dir", str(out), "--resume", "--no-progress", "--data", a.data]
            + ["--variant", a.variant, "--epochs", str(a.epochs), "--train-limit", str(a.train_limit)]
            + ["--lr", str(a.lr), "--threads", str(a.threads)]
        )
    finally:
        Decoder.forward = forward  # type: ignore[method-assign]
    return [json.loads(line) for line in (out / "log.jsonl").read_text().splitlines() if line.strip()]


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--variant", default="inception")
    p.add_argument("--mode", choices=["full", "prefix", "both"], default="both")
    p.add_argument("--epochs", type=int, default=2)
    p.add_argument("--train-limit", type=int, default=5000)
    p.add_argument("--lr", type=float, default=2e-3)
    p.add_argument("--threads", type=int, default=1)
    p.add_argument("--data", default="data/curves.npz")
    p.add_argument("--out", default="runs/decoder-ab")
    a = p.parse_args()
    for mode in ["full", "prefix"] if a.mode == "both" else [a.mode]:
        log = run(mode, a)
        vals = ", ".join(f"{r['val_mse']:.3f}" for r in log)
        speed = sum(r["curves_per_s"] for r in log) / len(log)
        print(f"{a.variant} {mode}: validation MSE per epoch {vals}; {speed:.1f} curves/s")


if __name__ == "__main__":
    main()
