"""`curve-vae spacer`: the spacing guesser (training/spacer.py) — train it on the paper's curves, export it into a
model directory. Training is time-budgeted and resumable: run it again with --resume to carry on."""

from __future__ import annotations

import argparse
from pathlib import Path


def cmd_train(a: argparse.Namespace) -> int:
    import torch

    from curve_vae.training.spacer import train_spacer

    if a.threads:
        torch.set_num_threads(a.threads)
    best = train_spacer(a.run_dir, time_budget=a.time_budget, resume=a.resume, lr=a.lr, batch=a.batch, seed=a.seed)
    print(f"best held-out step → {best} (export it with curve-vae spacer export)")
    return 0


def cmd_export(a: argparse.Namespace) -> int:
    from curve_vae.files import refuse_overwrite
    from curve_vae.training.spacer import export_spacer

    refuse_overwrite(Path(a.model_dir) / "spacer.onnx", a.force, flag="--model-dir")
    path = export_spacer(
        a.checkpoint, a.model_dir, meta={"note": a.note} if a.note else None, version=a.version or None
    )
    print(f'wrote {path}; pose "learned" starts its natural fit from its guesses (the manifest names it)')
    return 0


def register(sub: argparse._SubParsersAction) -> None:
    r = sub.add_parser("spacer", help="the spacing guesser: train it, export it into a model")
    stages = r.add_subparsers(dest="stage", required=True)

    s = stages.add_parser("train", help="train on the paper's curves, drawn afresh each step (time-budgeted)")
    s.add_argument("--run-dir", default="runs/spacer", help="checkpoints go here (default: runs/spacer)")
    s.add_argument("--time-budget", type=float, default=600.0, help="seconds of training in all (default: 600)")
    s.add_argument("--resume", action="store_true", help="carry on from RUN_DIR/spacer-last.pt")
    s.add_argument("--lr", type=float, default=1e-3, help="peak learning rate, cosine over the budget (default: 1e-3)")
    s.add_argument("--batch", type=int, default=128, help="curves per step (default: 128)")
    s.add_argument("--seed", type=int, default=0, help="the curves drawn and the initial weights (default: 0)")
    s.add_argument("--threads", type=int, default=0, help="torch's threads (default: torch's own)")
    s.set_defaults(func=cmd_train)

    s = stages.add_parser("export", help="write the guesser into a model directory")
    s.add_argument(
        "checkpoint", help="a spacer checkpoint (RUN_DIR/spacer-best.pt), or an older model's spacer.npz to convert"
    )
    s.add_argument("--model-dir", required=True, help="the model directory whose reading it serves")
    s.add_argument("--version", default="", help="the model's new version (default: unchanged)")
    s.add_argument("--note", default="", help="how the guesser was trained, in words, kept in the manifest")
    s.add_argument("--force", action="store_true", help="replace the model directory's guesser if it has one")
    s.set_defaults(func=cmd_export)
