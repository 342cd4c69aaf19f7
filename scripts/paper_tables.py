"""Reproduce the paper's tables at a reduced, stated budget: one training run per row.

    .venv/bin/python scripts/paper_tables.py --table 1 --epochs 6 --train-limit 20000
    .venv/bin/python scripts/paper_tables.py --table 2 ...
    .venv/bin/python scripts/paper_tables.py --table lap ...   # Laplacian ablation (Fig. 2/3)

Every row uses the same data set, schedule and budget (epochs × curves); runs land in
runs/tables/<row>/ and are resumable (rerun the same command after a cut-off). The script
prints a Markdown table of test-set MSE (paper eq. 4) and output roughness beside the
paper's numbers, and writes it to runs/tables/table_<t>.md.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from curve_vae.cli import main as cli

PAPER = {
    "1": [
        ("cnn1", 32, 1.0, 1.018),
        ("cnn2", 32, 1.0, 0.696),
        ("cnn3", 32, 1.0, 0.549),
        ("cnn4", 32, 1.0, 0.364),
        ("cnn5", 32, 1.0, 0.250),
        ("inception", 32, 1.0, 0.099),
    ],
    "2": [
        ("inception", 8, 1.0, 12.075),
        ("inception", 16, 1.0, 0.670),
        ("inception", 32, 1.0, 0.099),
        ("inception", 64, 1.0, 0.090),
    ],
    "lap": [("inception", 32, 0.0, None), ("inception", 32, 1.0, 0.099)],
}


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--table", choices=list(PAPER), required=True)
    p.add_argument("--epochs", type=int, default=6, help="epochs per row (default: 6)")
    p.add_argument("--train-limit", type=int, default=20_000, help="training curves per epoch (default: 20000)")
    p.add_argument("--lr", type=float, default=2e-3, help="onecycle peak learning rate (default: 2e-3)")
    p.add_argument("--data", default="data/curves.npz", help="data set cache (default: data/curves.npz)")
    p.add_argument("--out", default="runs/tables", help="run directories (default: runs/tables)")
    a = p.parse_args()
    rows = []
    for variant, latent, lap, paper in PAPER[a.table]:
        name = f"{variant}_z{latent}_lap{lap:g}_e{a.epochs}_n{a.train_limit}"
        run = Path(a.out) / name
        if not (run / "report.json").exists():
            cli(
                [
                    "train",
                    "--run-dir",
                    str(run),
                    "--resume",
                    "--no-progress",
                    "--data",
                    a.data,
                    "--variant",
                    variant,
                    "--latent-dim",
                    str(latent),
                    "--lap-weight",
                    str(lap),
                    "--epochs",
                    str(a.epochs),
                    "--train-limit",
                    str(a.train_limit),
                    "--lr",
                    str(a.lr),
                ]
            )
        rep = json.loads((run / "report.json").read_text())["test_sets"]["test"]
        rows.append((variant, latent, lap, paper, rep))
    budget = f"{a.epochs} epochs × {a.train_limit} curves, onecycle lr {a.lr:g}, batch 128, fp32"
    lines = [
        f"Budget per row: {budget}.",
        "",
        "| network | latent | Laplacian | paper MSE | our MSE | median | roughness out / in (°) |",
        "|---|---|---|---|---|---|---|",
    ]
    for variant, latent, lap, paper, r in rows:
        lines.append(
            f"| {variant} | {latent} | {lap:g} | {paper if paper is not None else '—'} | {r['mse']:.3f} | "
            f"{r['mse_median']:.3f} | {r['smoothness_output']['roughness']:.3f} / "
            f"{r['smoothness_input']['roughness']:.3f} |"
        )
    text = "\n".join(lines) + "\n"
    Path(a.out).mkdir(parents=True, exist_ok=True)
    (Path(a.out) / f"table_{a.table}.md").write_text(text)
    print(text)


if __name__ == "__main__":
    main()
