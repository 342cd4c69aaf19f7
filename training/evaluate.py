"""Evaluation (paper §3.4, §4): reconstruction MSE (eq. 4), tangent smoothness, figures.

Works on a torch checkpoint or on an exported model directory (ONNX, as the service runs
it), so the shipped artefacts are measured exactly as users receive them.

Length (~430 lines): the reports and the figures drawn from them; the figures (plot_*) are the
part to move into their own module when it grows again (issue 20).
"""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from geometry import mse_per_curve, self_intersects, smoothness
from training.io import atomic_path, atomic_write_text

Reconstructor = Callable[[np.ndarray], np.ndarray]  # (B, N, 2) → (B, N, 2), decoding the mean
Encoder = Callable[[np.ndarray], np.ndarray]  # (B, N, 2) → (B, Z) latent means
Decoder = Callable[[np.ndarray], np.ndarray]  # (B, Z) → (B, N, 2)


def onnx_codec(model_dir: str | Path) -> tuple[Encoder, Decoder, dict[str, Any]]:
    """Encoder/decoder callables over the ONNX graphs of an exported model, and its manifest."""
    import onnxruntime as ort

    model_dir = Path(model_dir)
    manifest = json.loads((model_dir / "manifest.json").read_text())
    enc = ort.InferenceSession(str(model_dir / "encoder.onnx"), providers=["CPUExecutionProvider"])
    dec = ort.InferenceSession(str(model_dir / "decoder.onnx"), providers=["CPUExecutionProvider"])

    def encode(curves: np.ndarray) -> np.ndarray:
        return enc.run(["mean"], {"curves": np.ascontiguousarray(curves, np.float32)})[0]

    def decode(z: np.ndarray) -> np.ndarray:
        return dec.run(["curves"], {"latent": np.ascontiguousarray(z, np.float32)})[0]

    return encode, decode, manifest


def torch_codec(checkpoint: str | Path) -> tuple[Encoder, Decoder, dict[str, Any]]:
    """Encoder/decoder callables over a torch checkpoint (last.pt, best.pt or vae.pt)."""
    import torch

    from training.model import VAE, ModelConfig

    ckpt = torch.load(checkpoint, map_location="cpu", weights_only=True)
    model = VAE(ModelConfig(**ckpt["model_config"]))
    model.load_state_dict(ckpt["model"])
    model.eval()

    @torch.no_grad()
    def encode(curves: np.ndarray) -> np.ndarray:
        return model.encoder(torch.as_tensor(curves, dtype=torch.float32))[0].numpy()

    @torch.no_grad()
    def decode(z: np.ndarray) -> np.ndarray:
        return model.decoder(torch.as_tensor(z, dtype=torch.float32)).numpy()

    return encode, decode, {"model_config": ckpt["model_config"]}


def batched(fn: Callable[[np.ndarray], np.ndarray], x: np.ndarray, batch: int = 500) -> np.ndarray:
    return np.concatenate([fn(x[i : i + batch]) for i in range(0, len(x), batch)])


def evaluate_set(curves: np.ndarray, recon: np.ndarray) -> dict[str, Any]:
    """The report of one test set: eq. 4 MSE statistics and smoothness of inputs vs outputs."""
    mse = mse_per_curve(curves, recon)
    s_in, s_out = smoothness(curves), smoothness(recon)
    d = np.asarray(curves, np.float64) - np.asarray(recon, np.float64)
    by_point = np.mean(d * d, axis=(0, 2))  # eq. 4 at each point index, over the set
    ends = 10
    return {
        "n_curves": len(curves),
        "mse": float(mse.mean()),  # paper eq. 4, averaged over the set (Table 1's number)
        "mse_median": float(np.median(mse)),
        "mse_p95": float(np.percentile(mse, 95)),
        "mse_max": float(mse.max()),
        # where along the curve the error sits: the end points are the hardest
        "mse_first_point": float(by_point[0]),
        "mse_last_point": float(by_point[-1]),
        f"error_share_first_last_{ends}_points": float(
            (by_point[:ends].sum() + by_point[-ends:].sum()) / max(by_point.sum(), 1e-300)
        ),
        "smoothness_input": {k: float(v.mean()) for k, v in s_in.items()},
        "smoothness_output": {k: float(v.mean()) for k, v in s_out.items()},
        "self_intersecting_outputs": float(self_intersects(recon).mean()),
    }


def interpolation_report(
    encode: Encoder, decode: Decoder, curves: np.ndarray, *, pairs: int = 200, steps: int = 5, seed: int = 0
) -> dict[str, Any]:
    """Latent vs point-wise interpolation of random test pairs (paper eq. 9, Fig. 10)."""
    rng = np.random.default_rng(seed)
    idx = rng.choice(len(curves), size=(pairs, 2), replace=True)
    idx = idx[idx[:, 0] != idx[:, 1]]
    w = np.linspace(0, 1, steps)[1:-1]  # the interior steps: the new curves
    mu = encode(curves[idx.reshape(-1)]).reshape(len(idx), 2, -1)
    z = w[None, :, None] * mu[:, None, 0] + (1 - w[None, :, None]) * mu[:, None, 1]  # (P, S, Z)
    latent = decode(z.reshape(-1, z.shape[-1])).reshape(len(idx), len(w), *curves.shape[1:])
    a, b = curves[idx[:, 0]], curves[idx[:, 1]]
    pointwise = w[None, :, None, None] * a[:, None] + (1 - w[None, :, None, None]) * b[:, None]
    out: dict[str, Any] = {"pairs": len(idx), "steps": steps}
    for name, c in (("latent", latent), ("pointwise", pointwise)):
        flat = c.reshape(-1, *curves.shape[1:])
        s = smoothness(flat)
        out[name] = {
            "self_intersecting": float(self_intersects(flat).mean()),
            **{k: float(v.mean()) for k, v in s.items()},
        }
    return out


def nearest_distances(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """For each curve of a (N, n, 2), the RMS point distance to its nearest curve of b (M, n, 2)."""
    x, y = a.reshape(len(a), -1).astype(np.float64), b.reshape(len(b), -1).astype(np.float64)
    d2 = (x * x).sum(1)[:, None] + (y * y).sum(1)[None, :] - 2 * x @ y.T
    return np.sqrt(np.maximum(d2.min(axis=1), 0.0) / a.shape[1])


def sample_quality(samples: np.ndarray, data: np.ndarray, reference: np.ndarray) -> dict[str, float]:
    """How generated curves compare with real ones (all (N, n, 2) in the model plane).

    coverage: mean distance from each held-out data curve to its nearest sample, over the same
    figure for a second set of real curves (`reference`, as many as the samples); precision:
    mean distance from each sample to its nearest data curve, over the reference's. 1 means
    "as close as real data"; above 1, samples miss parts of the data (coverage) or lie off it.
    """
    size = lambda c: np.linalg.norm(np.ptp(c, axis=1), axis=1)  # bounding-box diagonals
    return {
        "self_intersecting": float(self_intersects(samples).mean()),
        "roughness": float(smoothness(samples)["roughness"].mean()),
        "roughness_data": float(smoothness(data)["roughness"].mean()),
        "size_vs_data": float(size(samples).mean() / size(data).mean()),
        "coverage_vs_real": float(nearest_distances(data, samples).mean() / nearest_distances(data, reference).mean()),
        "precision_vs_real": float(nearest_distances(samples, data).mean() / nearest_distances(reference, data).mean()),
    }


def generation_report(
    runtime: Any, data: np.ndarray, reference: np.ndarray, *, seed: int = 0, max_draws: int = 10
) -> dict[str, Any]:
    """Samples of each prior the model has (learned, standard), as /sample makes them by default (valid: rejected
    and drawn again, here at most `max_draws` times: a model whose draws keep failing is reported as such without
    spending 50 decodes a curve) and every draw kept; as many samples as `reference` curves."""
    out: dict[str, Any] = {"n_samples": len(reference), "seed": seed}
    for prior in ("learned", "standard") if runtime.prior is not None else ("standard",):
        raw = runtime.sample(len(reference), seed=seed, prior=prior, valid=False)
        kept = runtime.sample(len(reference), seed=seed, prior=prior, valid=True, max_draws=max_draws)
        out[prior] = {
            "every_draw": {
                **sample_quality(raw.curves, data, reference),
                "implausible": float(1 - runtime.plausible(raw.curves).mean()),
            },
            "valid": {
                **sample_quality(kept.curves, data, reference),
                "rejected_share": kept.rejected / (kept.rejected + len(reference)),
                "invalid": kept.invalid,
            },
        }
    return out


# ---------------------------------------------------------------------------------- figures


def plot_samples(samples: np.ndarray, data: np.ndarray, path: Path, *, n: int = 16) -> None:
    """n generated curves beside n data curves, each in its own cell of the 128×128 plane."""
    plt = _plt()
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
    _save(fig, path)


def _plt():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _save(fig: Any, path: Path) -> None:
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format="png", dpi=110, bbox_inches="tight")
    _plt().close(fig)


def plot_reconstructions(curves: np.ndarray, recon: np.ndarray, path: Path, *, n: int = 8) -> None:
    """Targets (dashed blue) and reconstructions (red) with per-curve MSE (paper Fig. 6)."""
    plt = _plt()
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
    _save(fig, path)


def plot_tangents(
    curves: list[np.ndarray], labels: list[str], path: Path, *, every: int = 4, window: slice = slice(40, 90)
) -> None:
    """Unit tangents (paper eq. 8) as arrows on a stretch of each curve (paper Fig. 3)."""
    plt = _plt()
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
    _save(fig, path)


def plot_training(log_path: Path, path: Path) -> None:
    """Loss terms and validation MSE per epoch, from a run's log.jsonl."""
    plt = _plt()
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
    _save(fig, path)


def latent_sweep(encode: Encoder, decode: Decoder, a: np.ndarray, b: np.ndarray, steps: int) -> np.ndarray:
    """Decoded curves of eq. 9 from w=1 (curve a) to w=0 (curve b), `steps` of them."""
    w = np.linspace(1, 0, steps)
    mu = encode(np.stack([a, b]))
    return decode(w[:, None] * mu[0] + (1 - w[:, None]) * mu[1])


def plot_pair_interpolation(
    encode: Encoder, decode: Decoder, pairs: list[tuple[np.ndarray, np.ndarray]], path: Path, *, steps: int = 5
) -> None:
    """Each row: the two inputs, then `steps` decoded curves of eq. 9 from w=1 to w=0 (paper Fig. 11)."""
    plt = _plt()
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
    _save(fig, path)


def plot_latent_vs_pointwise(
    encode: Encoder, decode: Decoder, pairs: list[tuple[np.ndarray, np.ndarray]], path: Path, *, steps: int = 5
) -> None:
    """Each row: one pair blended in latent space (eq. 9) and point by point (paper Fig. 10).

    Titles give the mean roughness of the interior curves and how many of them self-intersect.
    """
    plt = _plt()
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
            crossing = int(self_intersects(inner).sum())
            ax.set_title(f"{name}: roughness {rough:.2f}°, {crossing}/{len(inner)} self-intersecting", fontsize=9)
            ax.set_aspect("equal")
            ax.set_xticks([])
            ax.set_yticks([])
    axes[0, 0].legend(fontsize=7, loc="best")
    _save(fig, path)


def plot_triplet(encode: Encoder, decode: Decoder, curves: np.ndarray, path: Path, *, steps: int = 4) -> None:
    """Three inputs and the barycentric grid of eq. 10 between them (paper Fig. 8)."""
    plt = _plt()
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
    _save(fig, path)


def plot_latent_tsne(encode: Encoder, curves: np.ndarray, path: Path, *, examples: int = 6, seed: int = 0) -> None:
    """t-SNE of the latent means, with a few curves drawn beside their points (paper Fig. 7)."""
    from sklearn.manifold import TSNE

    plt = _plt()
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
    _save(fig, path)


MIN_FIGURE_CURVES = 32  # the interpolation figures take curves 0-13; t-SNE needs more points than its perplexity


def run_evaluation(
    encode: Encoder,
    decode: Decoder,
    test_sets: dict[str, np.ndarray],
    out_dir: str | Path,
    *,
    log_path: Path | None = None,
    figures: bool = True,
    runtime: Any = None,
    suite_count: int = 0,
) -> dict[str, Any]:
    """Evaluate on each named test set; write report.json (and figures) into out_dir.

    runtime: the exported model as the service runs it (service.runtime.CurveRuntime): adds the
    generation report of its priors, the first test set held out and the second as the real reference,
    and with suite_count > 0 the family suite (training/suite.py) of that many curves per set.
    """
    out = Path(out_dir)
    report: dict[str, Any] = {"test_sets": {}}
    for name, curves in test_sets.items():
        recon = batched(lambda x: decode(encode(x)), curves)
        report["test_sets"][name] = evaluate_set(curves, recon)
        if len(curves) >= 2:  # a data set of one's own may hold a single test curve: no pairs to interpolate
            report["test_sets"][name]["interpolation"] = interpolation_report(encode, decode, curves)
        if figures:
            plot_reconstructions(curves, recon, out / f"reconstructions_{name}.png", n=min(8, len(curves)))
            plot_tangents([curves[0], recon[0]], ["input", "reconstruction"], out / f"tangents_{name}.png")
    first = next(iter(test_sets.values()))
    if runtime is not None and len(test_sets) >= 2:
        reference = list(test_sets.values())[1]
        report["generation"] = generation_report(runtime, first, reference)
        if figures:
            made = runtime.sample(16, seed=0)
            plot_samples(made.curves, first, out / "samples.png")
    if figures and len(first) >= MIN_FIGURE_CURVES:
        plot_pair_interpolation(
            encode, decode, [(first[0], first[1]), (first[2], first[3])], out / "interpolation_pair.png"
        )
        plot_triplet(encode, decode, first[4:7], out / "interpolation_triplet.png")
        plot_latent_vs_pointwise(
            encode,
            decode,
            [(first[i % len(first)], first[(i + 1) % len(first)]) for i in (8, 10, 12)],
            out / "interpolation_latent_vs_pointwise.png",
        )
        plot_latent_tsne(encode, first, out / "latent_tsne.png")
    if runtime is not None and suite_count > 0:
        from training.suite import paper_test_split, plot_suite, run_suite, suite_sets

        paper = paper_test_split()  # whatever the model was trained on: the suite's paper sets are the paper's
        report["families"] = run_suite(runtime, paper, count=suite_count)
        if figures:
            plot_suite(runtime, suite_sets(paper, suite_count), out / "families.png")
    if figures and log_path is not None and log_path.exists():
        plot_training(log_path, out / "training.png")
    atomic_write_text(out / "report.json", json.dumps(report, indent=2) + "\n")
    return report
