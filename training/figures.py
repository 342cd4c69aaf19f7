"""The evaluation's figures (paper Figs. 3, 6, 7, 8, 10, 11; samples, training curves, the family suite), drawn
from a model's encode/decode functions or from reports, and written atomically as PNG. matplotlib is imported
when a figure is drawn, not before.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np

from curve_vae.files import atomic_path
from curve_vae.geometry import mse_per_curve, self_intersects, smoothness
from curve_vae.training.evaluate import Decoder, Encoder, batched


def plot_samples(samples: np.ndarray, data: np.ndarray, path: Path, *, n: int = 16) -> None:
    """n generated curves beside n data curves, each in its own cell of the 128×128 plane."""
    plt = pyplot()
    fig, axes = plt.subplots(4, 2 * (n // 4), figsize=(2 * n // 4 * 1.6, 4 * 1.6), squeeze=False)
    for j, (curves, label, color) in enumerate(((samples, "samples", "tab:red"), (data, "data", "tab:blue"))):
        for i in range(n):
            ax = axes[i // (n // 4), j * (n // 4) + i % (n // 4)]
            ax.plot(*curves[i].T, color=color, lw=1.0)
            ax.set_xlim(-4, 132)
            ax.set_ylim(-4, 132)
            ax.set_aspect("equal")
            ax.set_xticks([])
            ax.set_yticks([])
        axes[0, j * (n // 4)].set_title(label, loc="left", fontsize=10)
    save_figure(fig, path)


def plot_beside(made: list[np.ndarray], real: list[np.ndarray], path: Path, *, n: int = 12, title: str = "") -> None:
    """n generated curves beside n real ones, in their own frame, every cell on the same scale (a family's sizes
    compare across the two columns)."""
    plt = pyplot()
    made, real = made[:n], real[:n]
    shown = np.concatenate([*made, *real])
    lo, hi = shown.min(axis=0), shown.max(axis=0)
    pad = 0.04 * float((hi - lo).max())
    lo, hi = lo - pad, hi + pad
    aspect = float((hi[1] - lo[1]) / (hi[0] - lo[0]))
    rows = -(-n // 2)
    cell = 1.8
    fig, axes = plt.subplots(rows, 4, figsize=(4 * cell, rows * cell * min(max(aspect, 0.25), 1.5)), squeeze=False)
    for j, (curves, label, color) in enumerate(((made, "sampled", "tab:red"), (real, "held out", "tab:blue"))):
        for i in range(rows * 2):
            ax = axes[i // 2, 2 * j + i % 2]
            if i < len(curves):
                ax.plot(*curves[i].T, color=color, lw=1.0)
            ax.set_xlim(lo[0], hi[0])
            ax.set_ylim(lo[1], hi[1])
            ax.set_aspect("equal")
            ax.set_xticks([])
            ax.set_yticks([])
        axes[0, 2 * j].set_title(f"{label}: {title}" if title and j == 0 else label, loc="left", fontsize=10)
    save_figure(fig, path)


def pyplot():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def save_figure(fig: Any, path: Path) -> None:
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format="png", dpi=110, bbox_inches="tight")
    pyplot().close(fig)


def plot_reconstructions(curves: np.ndarray, recon: np.ndarray, path: Path, *, n: int = 8) -> None:
    """Targets (dashed blue) and reconstructions (red) with per-curve MSE (paper Fig. 6)."""
    plt = pyplot()
    mse = mse_per_curve(curves[:n], recon[:n])
    cols = min(4, n)
    rows = -(-n // cols)
    fig, axes = plt.subplots(rows, cols, figsize=(3.2 * cols, 3.2 * rows), squeeze=False)
    for i, ax in enumerate(axes.flat):
        ax.set_axis_off()
        if i >= n:
            continue
        ax.plot(*curves[i].T, "b--", lw=1.2, label="target")
        ax.plot(*recon[i].T, "r-", lw=1.0, label="reconstruction")
        ax.set_aspect("equal")
        ax.set_title(f"MSE {mse[i]:.3f}", fontsize=9)
    axes.flat[0].legend(fontsize=7, loc="lower left")
    save_figure(fig, path)


def plot_suite(runtime: Any, sets: dict[str, tuple[str, list[np.ndarray]]], path: Path, *, n: int = 5) -> None:
    """A row per set: its first n curves (grey) and their reconstructions (colour), each in its own frame."""
    from curve_vae.training.suite import relative_rmse

    plt = pyplot()
    fig, axes = plt.subplots(len(sets), n, figsize=(1.7 * n, 1.7 * len(sets)), squeeze=False)
    for ax in axes.flat:  # a set of fewer than n curves leaves its last panels blank, not empty boxes
        ax.axis("off")
    for row, (name, (kind, curves)) in zip(axes, sets.items()):
        out = runtime.reconstruct(curves[:n]).curves
        rel = relative_rmse(curves[:n], out)
        for ax, c, o, r in zip(row, curves, out, rel):
            ax.plot(c[:, 0], c[:, 1], color="0.65", lw=2.4)
            ax.plot(o[:, 0], o[:, 1], color="tab:red", lw=0.9)
            ax.plot(*c[0], "o", color="0.3", ms=2.5)
            ax.set_title(f"{100 * r:.2f}%", fontsize=7, pad=1)
            ax.set_aspect("equal")
        row[0].text(-0.08, 0.5, f"{name}\n({kind})", transform=row[0].transAxes, ha="right", va="center", fontsize=7)
    fig.suptitle("grey: input (dot: first point) · red: reconstruction · relative RMSE", fontsize=8)
    fig.tight_layout(rect=(0.12, 0, 1, 0.98))
    path.parent.mkdir(parents=True, exist_ok=True)
    save_figure(fig, path)


def plot_tangents(
    curves: list[np.ndarray], labels: list[str], path: Path, *, every: int = 4, window: slice = slice(40, 90)
) -> None:
    """Unit tangents (paper eq. 8) as arrows on a stretch of each curve (paper Fig. 3)."""
    plt = pyplot()
    fig, axes = plt.subplots(1, len(curves), figsize=(4 * len(curves), 4), squeeze=False)
    for ax, c, label in zip(axes.flat, curves, labels):
        seg = c[window]
        d = np.diff(seg, axis=0)
        t = d / np.maximum(np.linalg.norm(d, axis=1, keepdims=True), 1e-12)
        length = 0.08 * np.ptp(seg, axis=0).max()  # arrows a fixed fraction of the stretch shown
        ax.plot(*seg.T, "k-", lw=0.8)
        ax.quiver(
            seg[:-1:every, 0],
            seg[:-1:every, 1],
            length * t[::every, 0],
            length * t[::every, 1],
            angles="xy",
            scale_units="xy",
            scale=1,
            width=0.006,
            color="tab:red",
        )
        rough = smoothness(c[None])["roughness"][0]
        ax.set_title(f"{label}\nroughness {rough:.3f}°", fontsize=9)
        ax.set_aspect("equal")
    save_figure(fig, path)


def plot_training(log_path: Path, path: Path) -> None:
    """Loss terms and validation MSE per epoch, from a run's log.jsonl."""
    plt = pyplot()
    rows = [json.loads(line) for line in log_path.read_text().splitlines() if line.strip()]
    ep = [r["epoch"] for r in rows]
    fig, axes = plt.subplots(1, 3, figsize=(13, 3.6), layout="constrained")
    axes[0].semilogy(ep, [r["train_mse"] for r in rows], label="train MSE")
    axes[0].semilogy(ep, [r["val_mse"] for r in rows], label="validation MSE")
    axes[0].axhline(0.099, color="gray", ls=":", label="paper (0.099)")
    axes[0].set_xlabel("epoch")
    axes[0].legend()
    axes[1].plot(ep, [r["train_kl"] for r in rows], label="KL", color="C0")
    axes[1].set_ylabel("KL", color="C0")
    lap = axes[1].twinx()  # the Laplacian term is ~100× smaller than the KL: its own scale
    lap.plot(ep, [r["train_lap"] for r in rows], label="Laplacian", color="C1")
    lap.set_ylabel("Laplacian", color="C1")
    axes[1].set_xlabel("epoch")
    axes[2].plot(ep, [r["lr"] for r in rows])
    axes[2].set_xlabel("epoch")
    axes[2].set_ylabel("learning rate")
    save_figure(fig, path)


def latent_sweep(encode: Encoder, decode: Decoder, a: np.ndarray, b: np.ndarray, steps: int) -> np.ndarray:
    """Decoded curves of eq. 9 from w=1 (curve a) to w=0 (curve b), `steps` of them."""
    w = np.linspace(1, 0, steps)
    mu = encode(np.stack([a, b]))
    return decode(w[:, None] * mu[0] + (1 - w[:, None]) * mu[1])


def plot_pair_interpolation(
    encode: Encoder, decode: Decoder, pairs: list[tuple[np.ndarray, np.ndarray]], path: Path, *, steps: int = 5
) -> None:
    """Each row: the two inputs, then `steps` decoded curves of eq. 9 from w=1 to w=0 (paper Fig. 11)."""
    plt = pyplot()
    w = np.linspace(1, 0, steps)
    fig, axes = plt.subplots(
        len(pairs), 3, figsize=(11, 3.4 * len(pairs)), squeeze=False, gridspec_kw={"width_ratios": [1, 1, 1.4]}
    )
    cmap = plt.get_cmap("viridis")
    for row, (a, b) in zip(axes, pairs):
        out = latent_sweep(encode, decode, a, b, steps)
        row[0].plot(*a.T, color=cmap(0.0))
        row[1].plot(*b.T, color=cmap(1.0))
        for i, c in enumerate(out):
            row[2].plot(*c.T, color=cmap(i / (steps - 1)), lw=1.2, label=f"w={w[i]:.2f}")
        row[0].set_title("curve 1")
        row[1].set_title("curve 2")
        row[2].set_title(f"latent interpolation, {steps} steps")
        for ax in row:
            ax.set_aspect("equal")
            ax.set_xticks([])
            ax.set_yticks([])
    axes[0, 2].legend(fontsize=7, loc="best")
    save_figure(fig, path)


def plot_latent_vs_pointwise(
    encode: Encoder, decode: Decoder, pairs: list[tuple[np.ndarray, np.ndarray]], path: Path, *, steps: int = 5
) -> None:
    """Each row: one pair blended in latent space (eq. 9) and point by point (paper Fig. 10).

    Titles give the mean roughness of the interior curves and how many of them self-intersect.
    """
    plt = pyplot()
    w = np.linspace(1, 0, steps)
    fig, axes = plt.subplots(len(pairs), 2, figsize=(9, 3.6 * len(pairs)), squeeze=False)
    cmap = plt.get_cmap("viridis")
    for row, (a, b) in zip(axes, pairs):
        latent = latent_sweep(encode, decode, a, b, steps)
        pointwise = w[:, None, None] * a[None] + (1 - w[:, None, None]) * b[None]
        for ax, curves, name in ((row[0], latent, "latent"), (row[1], pointwise, "point-wise")):
            for i, c in enumerate(curves):
                ax.plot(*c.T, color=cmap(i / (steps - 1)), lw=1.2, label=f"w={w[i]:.2f}")
            inner = curves[1:-1]
            rough = smoothness(inner)["roughness"].mean()
            crossing = int(np.sum(self_intersects(inner)))
            ax.set_title(f"{name}: roughness {rough:.2f}°, {crossing}/{len(inner)} self-intersecting", fontsize=9)
            ax.set_aspect("equal")
            ax.set_xticks([])
            ax.set_yticks([])
    axes[0, 0].legend(fontsize=7, loc="best")
    save_figure(fig, path)


def plot_triplet(encode: Encoder, decode: Decoder, curves: np.ndarray, path: Path, *, steps: int = 4) -> None:
    """Three inputs and the barycentric grid of eq. 10 between them (paper Fig. 8)."""
    plt = pyplot()
    mu = encode(curves[:3])
    fig, axes = plt.subplots(steps, steps, figsize=(2.6 * steps, 2.6 * steps))
    for i in range(steps):
        for j in range(steps):
            ax = axes[i, j]
            ax.set_axis_off()
            if i + j > steps - 1:
                continue
            w = np.array([steps - 1 - i - j, i, j]) / (steps - 1)
            c = decode((w @ mu)[None])[0]
            corner = np.isclose(w, 1).any()
            ax.plot(*c.T, color="tab:blue" if corner else "tab:red", lw=1.2)
            ax.set_title(f"w = ({w[0]:.2f}, {w[1]:.2f}, {w[2]:.2f})", fontsize=7)
            ax.set_aspect("equal")
    fig.suptitle("triplet interpolation: inputs decoded at the corners (blue), blends in red")
    save_figure(fig, path)


def plot_latent_tsne(encode: Encoder, curves: np.ndarray, path: Path, *, examples: int = 6, seed: int = 0) -> None:
    """t-SNE of the latent means, with a few curves drawn beside their points (paper Fig. 7)."""
    from sklearn.manifold import TSNE

    plt = pyplot()
    mu = batched(encode, curves)
    xy = TSNE(n_components=2, random_state=seed, init="pca", perplexity=30).fit_transform(mu)
    fig = plt.figure(figsize=(12, 6))
    ax = fig.add_axes((0.05, 0.05, 0.5, 0.9))
    ax.scatter(*xy.T, s=4, c="lightgray")
    picks = np.random.default_rng(seed).choice(len(curves), size=examples, replace=False)
    colors = plt.get_cmap("tab10")
    for k, i in enumerate(picks):
        ax.scatter(*xy[i], s=40, color=colors(k), edgecolor="k")
        sub = fig.add_axes((0.58 + 0.14 * (k % 3), 0.52 - 0.45 * (k // 3), 0.13, 0.4))
        sub.plot(*curves[i].T, color=colors(k))
        sub.set_aspect("equal")
        sub.set_xticks([])
        sub.set_yticks([])
    ax.set_title(f"t-SNE of {len(curves)} latent means")
    ax.set_xticks([])
    ax.set_yticks([])
    save_figure(fig, path)
