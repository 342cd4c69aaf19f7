"""`curve-vae ranker`: the reading ranker (training/ranker.py) — label curves through the frozen model, train on the
labels, export into a model directory. Every stage is time-budgeted and resumable: run it again to carry on."""

from __future__ import annotations

import argparse
from pathlib import Path


def cmd_label(a: argparse.Namespace) -> int:
    from curve_vae.training.ranker_labels import label_curves

    files = label_curves(
        a.model_dir,
        a.out,
        curves=a.curves,
        seed=a.seed,
        chunk=a.chunk,
        time_budget=a.time_budget,
        **({"families": a.families} if a.families else {}),
    )
    print(f"{len(files)} label files in {a.out} (train on them with curve-vae ranker train)")
    return 0


def cmd_train(a: argparse.Namespace) -> int:
    from curve_vae.training.ranker import train_ranker

    best = train_ranker(
        a.labels,
        a.run_dir,
        time_budget=a.time_budget,
        resume=a.resume,
        init_from=a.init_from or None,
        lr=a.lr,
        choice_weight=a.choice_weight,
        seed=a.seed,
    )
    print(f"best held-out epoch → {best} (export it with curve-vae ranker export)")
    return 0


def cmd_export(a: argparse.Namespace) -> int:
    from curve_vae.files import refuse_overwrite
    from curve_vae.training.ranker import export_ranker

    refuse_overwrite(Path(a.model_dir) / "ranker.onnx", a.force, flag="--model-dir")
    meta = {"note": a.note} if a.note else None
    path = export_ranker(a.checkpoint, a.model_dir, meta=meta, default=not a.not_default, version=a.version or None)
    if a.checkpoint.endswith(".npz"):
        reading = "converted from its numpy weights, the model's reading as it was"
    elif a.not_default:
        reading = 'pose "learned" is there to ask for'
    else:
        reading = 'the model\'s reading is now pose "learned"'
    print(f"wrote {path}; {reading} (the manifest names it)")
    return 0


def _families(text: str) -> list[str]:
    from curve_vae.training.families import RANKER_FAMILIES

    unknown = [name for name in text.split(",") if name not in RANKER_FAMILIES]
    if unknown:
        raise argparse.ArgumentTypeError(f"unknown families {unknown}: choose from {', '.join(RANKER_FAMILIES)}")
    return text.split(",")


def register(sub: argparse._SubParsersAction) -> None:
    r = sub.add_parser("ranker", help="the reading ranker: label curves, train it, export it into a model")
    stages = r.add_subparsers(dest="stage", required=True)

    s = stages.add_parser("label", help="read user-like curves every way the search does, through the frozen model")
    s.add_argument("--model-dir", default="models", help="the frozen model (default: models)")
    s.add_argument("--out", default="data/ranker", help="label chunks go here (default: data/ranker)")
    s.add_argument("--curves", type=int, default=12_000, help="curves to label (default: 12000)")
    s.add_argument("--seed", type=int, default=1, help="seed of the curves; each seed its own files (default: 1)")
    s.add_argument("--chunk", type=int, default=250, help="curves per file (default: 250)")
    s.add_argument("--time-budget", type=float, default=0.0, help="seconds, then stop at a chunk's end (0: none)")
    s.add_argument(
        "--families",
        type=_families,
        default=None,
        help="comma-separated family names (default: the VAE's training families; closed: closed outlines)",
    )
    s.set_defaults(func=cmd_label)

    s = stages.add_parser("train", help="train the ranker on the label chunks (time-budgeted, resumable)")
    s.add_argument("--labels", default="data/ranker", help="the label chunks (default: data/ranker)")
    s.add_argument("--run-dir", default="runs/ranker", help="checkpoints go here (default: runs/ranker)")
    s.add_argument("--time-budget", type=float, default=600.0, help="seconds of training in all (default: 600)")
    s.add_argument("--resume", action="store_true", help="carry on from RUN_DIR/ranker-last.pt")
    s.add_argument("--init-from", default="", help="start a new run from a ranker checkpoint's weights")
    s.add_argument(
        "--choice-weight",
        type=float,
        default=0.3,
        help="weight of the cross-entropy on each curve's best (default: 0.3)",
    )
    s.add_argument("--lr", type=float, default=2e-3, help="peak learning rate, cosine over the budget (default: 2e-3)")
    s.add_argument("--seed", type=int, default=0, help="held-out split and initial weights (default: 0)")
    s.set_defaults(func=cmd_train)

    s = stages.add_parser("export", help='write the ranker into a model directory; its reading becomes "learned"')
    s.add_argument(
        "checkpoint", help="a ranker checkpoint (RUN_DIR/ranker-best.pt), or an older model's ranker.npz to convert"
    )
    s.add_argument("--model-dir", required=True, help="the model directory whose graphs it was trained against")
    s.add_argument("--not-default", action="store_true", help='keep the model\'s reading; "learned" only on request')
    s.add_argument("--version", default="", help="the model's new version (default: unchanged)")
    s.add_argument("--note", default="", help="how the ranker was trained, in words, kept in the manifest")
    s.add_argument("--force", action="store_true", help="replace the model directory's ranker if it has one")
    s.set_defaults(func=cmd_export)
