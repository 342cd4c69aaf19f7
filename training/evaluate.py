"""Evaluation (paper §3.4, §4): reconstruction MSE (eq. 4), tangent smoothness, interpolation and generation.

Works on a torch checkpoint or on an exported model directory (ONNX, as the service runs
it), so the shipped artefacts are measured exactly as users receive them.

The figures drawn from these reports are `training/figures.py`.
"""

from __future__ import annotations

import json
from collections.abc import Callable
from dataclasses import asdict
from pathlib import Path
from typing import Any

import numpy as np

from curve_vae.files import atomic_write_text
from curve_vae.geometry import mse_per_curve, self_intersects, simplex_grid, smoothness
from curve_vae.geometry.metrics import diagonal

Reconstructor = Callable[[np.ndarray], np.ndarray]  # (B, N, 2) → (B, N, 2), decoding the mean
Encoder = Callable[[np.ndarray], np.ndarray]  # (B, N, 2) → (B, Z) latent means
Decoder = Callable[[np.ndarray], np.ndarray]  # (B, Z) → (B, N, 2)


def onnx_codec(model_dir: str | Path) -> tuple[Encoder, Decoder, dict[str, Any]]:
    """Encoder/decoder callables over the ONNX graphs of an exported model, and its manifest: loaded as the
    service loads them (CurveRuntime: the manifest's tensor names, the graphs' sha256 checked), so what is
    measured is what users receive."""
    from curve_vae.inference.runtime import CurveRuntime

    return runtime_codec(CurveRuntime.load(model_dir, providers="cpu", warm_up=False))


def runtime_codec(runtime: Any) -> tuple[Encoder, Decoder, dict[str, Any]]:
    """Encoder (latent means) and decoder callables in the model plane over a loaded CurveRuntime, and its manifest."""
    graphs = runtime.graphs
    return (lambda curves: graphs.encode(curves)[0]), graphs.decode_model, runtime.manifest.to_json()


def torch_codec(checkpoint: str | Path) -> tuple[Encoder, Decoder, dict[str, Any]]:
    """Encoder/decoder callables over a torch checkpoint (last.pt, best.pt or vae.pt)."""
    import torch

    from curve_vae.training.checkpoint import model_from_checkpoint

    model = model_from_checkpoint(checkpoint)

    @torch.no_grad()
    def encode(curves: np.ndarray) -> np.ndarray:
        return model.encoder(torch.as_tensor(curves, dtype=torch.float32))[0].numpy()

    @torch.no_grad()
    def decode(z: np.ndarray) -> np.ndarray:
        return model.decoder(torch.as_tensor(z, dtype=torch.float32)).numpy()

    return encode, decode, {"model_config": asdict(model.cfg)}


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
        "self_intersecting_outputs": float(np.mean(self_intersects(recon))),
    }


def interpolation_report(
    encode: Encoder, decode: Decoder, curves: np.ndarray, *, pairs: int = 200, steps: int = 5, seed: int = 0
) -> dict[str, Any]:
    """Latent vs point-wise interpolation of random test pairs (paper eq. 9, Fig. 10)."""
    rng = np.random.default_rng(seed)
    idx = rng.choice(len(curves), size=(pairs, 2), replace=True)
    idx = idx[idx[:, 0] != idx[:, 1]]
    w = simplex_grid(2, steps)[1:-1]  # (S, 2): eq. 9's interior steps, the new curves (as /interpolate mixes)
    mu = encode(curves[idx.reshape(-1)]).reshape(len(idx), 2, -1)
    z = np.einsum("sk,pkz->psz", w, mu)
    latent = decode(z.reshape(-1, z.shape[-1])).reshape(len(idx), len(w), *curves.shape[1:])
    pointwise = np.einsum("sk,pknd->psnd", w, curves[idx])
    out: dict[str, Any] = {"pairs": len(idx), "steps": steps}
    for name, c in (("latent", latent), ("pointwise", pointwise)):
        flat = c.reshape(-1, *curves.shape[1:])
        s = smoothness(flat)
        out[name] = {
            "self_intersecting": float(np.mean(self_intersects(flat))),
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
    return {
        "self_intersecting": float(np.mean(self_intersects(samples))),
        "roughness": float(smoothness(samples)["roughness"].mean()),
        "roughness_data": float(smoothness(data)["roughness"].mean()),
        "size_vs_data": float(diagonal(samples).mean() / diagonal(data).mean()),
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
                "implausible": float(1 - runtime.sampler.plausible(raw.curves).mean()),
            },
            "valid": {
                **sample_quality(kept.curves, data, reference),
                "rejected_share": kept.rejected / (kept.rejected + len(reference)),
                "invalid": kept.invalid,
            },
        }
    return out


MIN_FIGURE_CURVES = 32  # the interpolation figures take curves 0-13; t-SNE needs more points than its perplexity


def _test_set_reports(
    encode: Encoder, decode: Decoder, test_sets: dict[str, np.ndarray], out: Path, figures: bool
) -> dict[str, Any]:
    """Each test set's report (reconstruction, and interpolation where it has a pair), with its figures if asked."""
    from curve_vae.training.figures import plot_reconstructions, plot_tangents

    reports: dict[str, Any] = {}
    for name, curves in test_sets.items():
        recon = batched(lambda x: decode(encode(x)), curves)
        reports[name] = evaluate_set(curves, recon)
        if len(curves) >= 2:  # a data set of one's own may hold a single test curve: no pairs to interpolate
            reports[name]["interpolation"] = interpolation_report(encode, decode, curves)
        if figures:
            plot_reconstructions(curves, recon, out / f"reconstructions_{name}.png", n=min(8, len(curves)))
            plot_tangents([curves[0], recon[0]], ["input", "reconstruction"], out / f"tangents_{name}.png")
    return reports


def _interpolation_figures(encode: Encoder, decode: Decoder, first: np.ndarray, out: Path) -> None:
    """The paper's interpolation figures and the latent t-SNE, from the first test set's curves."""
    from curve_vae.training.figures import (
        plot_latent_tsne,
        plot_latent_vs_pointwise,
        plot_pair_interpolation,
        plot_triplet,
    )

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


def _family_suite(
    runtime: Any, suite_count: int, out: Path, figures: bool, refine: int = 0
) -> tuple[dict[str, Any], dict[str, Any] | None]:
    """The family suite's report (training/suite.py) on the paper's test split, with its figure if asked; with
    `refine`, also the same sets reconstructed with that many fitting steps (the request option)."""
    from curve_vae.training.figures import plot_suite
    from curve_vae.training.suite import paper_test_split, run_suite, suite_sets

    paper = paper_test_split()  # whatever the model was trained on: the suite's paper sets are the paper's
    sets = suite_sets(paper, suite_count)
    report = run_suite(runtime, sets)
    refined = {"refine": refine, "sets": run_suite(runtime, sets, refine=refine)} if refine > 0 else None
    if figures:
        plot_suite(runtime, sets, out / "families.png")
    return report, refined


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
    suite_refine: int = 0,
    morph_count: int = 0,
) -> dict[str, Any]:
    """Evaluate on each named test set; write report.json (and figures) into out_dir.

    runtime: the exported model as the service runs it (inference.runtime.CurveRuntime): adds the
    generation report of its priors, the first test set held out and the second as the real reference,
    and with suite_count > 0 the family suite (training/suite.py) of that many curves per set (with
    suite_refine > 0 also refined by that many fitting steps, as report["families_refined"] = {"refine": steps,
    "sets": …}), and with morph_count > 0 the morph suite (training/morphs.py) of that many pairs.
    """
    from curve_vae.training.figures import plot_samples, plot_training

    out = Path(out_dir)
    report: dict[str, Any] = {"test_sets": _test_set_reports(encode, decode, test_sets, out, figures)}
    first = next(iter(test_sets.values()))
    if runtime is not None and len(test_sets) >= 2:
        reference = list(test_sets.values())[1]
        report["generation"] = generation_report(runtime, first, reference)
        if figures:
            made = runtime.sample(16, seed=0)
            plot_samples(made.curves, first, out / "samples.png")
    if figures and len(first) >= MIN_FIGURE_CURVES:
        _interpolation_figures(encode, decode, first, out)
    if runtime is not None and suite_count > 0:
        report["families"], refined = _family_suite(runtime, suite_count, out, figures, suite_refine)
        if refined is not None:
            report["families_refined"] = refined
    if runtime is not None and morph_count > 0:
        from curve_vae.training.morphs import morph_pairs, run_morphs
        from curve_vae.training.suite import paper_test_split

        report["morphs"] = run_morphs(runtime, morph_pairs(paper_test_split(), morph_count))
    if figures and log_path is not None and log_path.exists():
        plot_training(log_path, out / "training.png")
    atomic_write_text(out / "report.json", json.dumps(report, indent=2) + "\n")
    return report
