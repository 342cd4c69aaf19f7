"""`curve-vae dataset`: the curve data set of a configuration, generated or checked (training/data.py)."""

from __future__ import annotations

import argparse
from pathlib import Path

from curve_vae.commands.options import (
    add_data_options,
    data_config,
    data_path,
)
from curve_vae.files import refuse_overwrite


def cmd_dataset(a: argparse.Namespace) -> int:
    import time

    from curve_vae.training.data import load_or_generate
    from curve_vae.training.figures import pyplot, save_figure

    if a.preview:
        refuse_overwrite(a.preview, a.force, "--preview")
    t = time.perf_counter()
    path = data_path(a, data_config(a))
    ds = load_or_generate(data_config(a), path, workers=a.workers)
    dt = time.perf_counter() - t
    print(
        f"{path}: train {ds.train.shape}, val {ds.val.shape}, test {ds.test.shape} "
        f"in {dt:.1f} s; coordinates in [{ds.train.min():.1f}, {ds.train.max():.1f}]"
    )
    if a.preview:
        plt = pyplot()
        fig, axes = plt.subplots(3, 6, figsize=(13, 6.5))
        for ax, c in zip(axes.flat, ds.train[:18]):
            ax.plot(*c.T, lw=1)
            ax.plot(*c[0], "go", ms=3)
            ax.set_xlim(0, 128)
            ax.set_ylim(0, 128)
            ax.set_aspect("equal")
            ax.set_xticks([])
            ax.set_yticks([])
        fig.suptitle("training curves (green: first point)")
        save_figure(fig, Path(a.preview))
        print(f"preview: {a.preview}")
    return 0


def register(sub: argparse._SubParsersAction) -> None:
    s = sub.add_parser("dataset", help="generate (or check) the cached curve data set")
    add_data_options(s)
    s.add_argument("--preview", default="", help="also write a PNG grid of training curves to this path")
    s.set_defaults(func=cmd_dataset)
