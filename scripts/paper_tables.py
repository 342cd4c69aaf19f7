"""Reproduce the paper's tables at a reduced, stated budget: one training run per row.

    .venv/bin/python scripts/paper_tables.py --table 1      # CNN_1 … CNN_6 (paper Table 1)
    .venv/bin/python scripts/paper_tables.py --table 2      # latent 8/16/32/64 (paper Table 2)
    .venv/bin/python scripts/paper_tables.py --table lap    # Laplacian ablation (Fig. 2/3)

Every row uses the same data set, schedule and budget (epochs × curves per epoch); runs
land in runs/tables/<row>/ and are resumable (rerun the same command after a cut-off;
finished rows are reused, so the Inception/latent-32/λ=1 row is trained once for all
three tables). The script prints a Markdown table of test-set MSE (paper eq. 4) and
output smoothness beside the paper's numbers and writes it to runs/tables/table_<t>.md.
`--table lap` also draws the tangent figure with and without the Laplacian term
(paper Fig. 3) into --figures.
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


def run_name(variant: str, latent: int, lap: float, epochs: int, train_limit: int, init: str = "") -> str:
    return f"{variant}_z{latent}_lap{lap:g}_e{epochs}_n{train_limit}" + (f"_from-{init}" if init else "")


def fresh_mse(run: Path, seed: int) -> float:
    """Test MSE of a run's best weights on 1,000 curves of a seed never used in training."""
    cache = run / f"fresh_seed_{seed}.json"
    if not cache.exists():
        from curve_vae.files import atomic_write_text
        from curve_vae.geometry import mse_per_curve
        from curve_vae.training.data import DataConfig, generate_curves
        from curve_vae.training.evaluate import batched, torch_codec

        cfg = DataConfig()
        curves, _ = generate_curves(1000, seed, n_ctrl=cfg.n_ctrl, n_points=cfg.n_points)
        encode, decode, _ = torch_codec(run / "best.pt")
        recon = batched(lambda x: decode(encode(x)), curves)
        atomic_write_text(cache, json.dumps({"mse": float(mse_per_curve(curves, recon).mean())}) + "\n")
    return json.loads(cache.read_text())["mse"]


def _init_label(path: str) -> str:
    """A short label of the starting weights: the model version of a model directory's manifest, else the file stem."""
    if not path:
        return ""
    manifest = Path(path).parent / "manifest.json"
    if manifest.exists():
        return "v" + json.loads(manifest.read_text()).get("version", Path(path).stem)
    return Path(path).stem


def laplacian_figure(runs: list[tuple[float, Path]], data: str, out: Path, *, curve: int = 0) -> None:
    """Tangents of one test curve: the input, then each run's reconstruction (paper Fig. 3)."""
    from curve_vae.training.data import DataConfig, load_or_generate
    from curve_vae.training.evaluate import torch_codec
    from curve_vae.training.figures import plot_tangents

    test = load_or_generate(DataConfig(), data).test[curve : curve + 1]
    curves, labels = [test[0]], ["input B-spline"]
    for lap, run in runs:
        encode, decode, _ = torch_codec(run / "best.pt")
        curves.append(decode(encode(test))[0])
        labels.append(f"reconstruction, λ_lap = {lap:g}")
    plot_tangents(curves, labels, out)


def _parse_args() -> argparse.Namespace:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--table", choices=list(PAPER), required=True)
    p.add_argument("--epochs", type=int, default=5, help="epochs per row (default: 5)")
    p.add_argument("--train-limit", type=int, default=10_000, help="training curves per epoch (default: 10000)")
    p.add_argument("--lr", type=float, default=2e-3, help="onecycle peak learning rate (default: 2e-3)")
    p.add_argument("--threads", type=int, default=0, help="CPU threads per run (default: 0 = torch's choice)")
    p.add_argument("--data", default="data/curves.npz", help="data set cache (default: data/curves.npz)")
    p.add_argument("--out", default="runs/tables", help="run directories (default: runs/tables)")
    p.add_argument("--fresh-seed", type=int, default=7919, help="seed of the second test set (default: 7919)")
    p.add_argument(
        "--init-from",
        default="",
        help="start every row from these weights instead of from scratch (e.g. models/vae.pt; "
        "rows whose architecture differs cannot use it)",
    )
    p.add_argument("--figures", default="docs/figures", help="--table lap: figure folder (default: docs/figures)")
    return p.parse_args()


def _train_row(run: Path, variant: str, latent: int, lap: float, a: argparse.Namespace) -> None:
    """`curve-vae train` of one row into `run` (resumed if cut off before), its report.json included."""
    args = ["train", "--run-dir", str(run), "--resume", "--no-progress", "--data", a.data]
    args += ["--variant", variant, "--latent-dim", str(latent), "--lap-weight", str(lap)]
    args += ["--epochs", str(a.epochs), "--train-limit", str(a.train_limit), "--lr", str(a.lr)]
    if a.threads:
        args += ["--threads", str(a.threads)]
    if a.init_from:
        args += ["--init-from", a.init_from]
    cli(args)


def _row_results(run: Path, fresh_seed: int) -> tuple[dict, float]:
    """A trained row's report (with the fresh-curve MSE added) and its training seconds."""
    rep = json.loads((run / "report.json").read_text())
    log = [json.loads(line) for line in (run / "log.jsonl").read_text().splitlines() if line.strip()]
    rep["fresh_mse"] = fresh_mse(run, fresh_seed)
    return rep, sum(r["seconds"] for r in log)


def _table(rows: list[tuple], a: argparse.Namespace, init: str) -> str:
    """The Markdown table: the budget, then a row per run beside the paper's MSE."""
    budget = (
        f"{a.epochs} epochs × {a.train_limit:,} curves ({a.epochs * a.train_limit:,} curves seen), "
        f"one-cycle peak lr {a.lr:g}, batch 128, fp32, "
        + (f"starting from {a.init_from} ({init})" if a.init_from else "from scratch")
    )
    lines = [
        f"Budget per row: {budget}.",
        "",
        "| network | latent | λ_lap | paper MSE | MSE, test split | MSE, fresh curves | roughness out / in (°) "
        "| self-intersecting | latent-interpolant roughness | train time (s) |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    for variant, latent, lap, paper, rep, seconds in rows:
        t = rep["test_sets"]["test"]
        name = "cnn6 (Inception)" if variant == "inception" else variant
        lines.append(
            f"| {name} | {latent} | {lap:g} | {paper if paper is not None else '—'} | "
            f"{t['mse']:.3f} | {rep['fresh_mse']:.3f} | "
            f"{t['smoothness_output']['roughness']:.2f} / {t['smoothness_input']['roughness']:.2f} | "
            f"{100 * t['self_intersecting_outputs']:.1f}% | "
            f"{rep['interpolation']['latent']['roughness']:.2f} | {seconds:.0f} |"
        )
    return "\n".join(lines) + "\n"


def main() -> None:
    a = _parse_args()
    init = _init_label(a.init_from)
    rows = []
    for variant, latent, lap, paper in PAPER[a.table]:
        run = Path(a.out) / run_name(variant, latent, lap, a.epochs, a.train_limit, init)
        if not (run / "report.json").exists():
            _train_row(run, variant, latent, lap, a)
        rows.append((variant, latent, lap, paper, *_row_results(run, a.fresh_seed)))
    text = _table(rows, a, init)
    Path(a.out).mkdir(parents=True, exist_ok=True)
    (Path(a.out) / f"table_{a.table}.md").write_text(text)
    print(text)
    if a.table == "lap":
        runs = [
            (lap, Path(a.out) / run_name(v, z, lap, a.epochs, a.train_limit, init)) for v, z, lap, _ in PAPER["lap"]
        ]
        figure = Path(a.figures) / ("tangents_laplacian.png" if not init else f"tangents_laplacian_from-{init}.png")
        laplacian_figure(runs, a.data, figure)
        print(f"figure: {figure}")


if __name__ == "__main__":
    main()
