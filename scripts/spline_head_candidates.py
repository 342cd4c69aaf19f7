"""Smooth output candidates side by side: the raw decoder, B-spline projection heads, fine-tuned heads (one run).

    pip download --no-deps aerosandbox==4.2.10 -d data/      # the airfoil database, once
    .venv/bin/python scripts/spline_head_candidates.py --weights models/vae.pt \\
        --heads 0 10 17 24 31 --checkpoint runs/spline31/best.pt \\
        --airfoils data/aerosandbox-4.2.10-py3-none-any.whl --out docs/spline_candidates.json

Every candidate is exported to ONNX and measured there, as the service runs it:
- the paper's test split and 1,000 fresh curves (seed 7919): MSE (eq. 4), roughness and
  self-intersection of reconstructions and of latent interpolants (200 pairs, 5 steps), with
  the point-wise blends of the same pairs for reference;
- 200 real airfoils through the service's runtime (frame "auto", spacing "arc_length"): RMSE
  relative to the bounding-box diagonal, the leading edge's error, roughness; and the floor
  each basis sets, the airfoil itself projected onto it;
- cost: decoder milliseconds per curve at batch 1 and 128, one onnxruntime thread.
Quote the cost as ratios to the raw decoder: absolute times drift with machine load.
"""

from __future__ import annotations

import argparse
import json
import tempfile
import time
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np
import onnxruntime as ort
import torch

from curve_vae.geometry import smoothness, spline_head
from curve_vae.inference.reading import Reading
from curve_vae.inference.runtime import CurveRuntime
from curve_vae.training.airfoils import load_airfoils
from curve_vae.training.checkpoint import model_from_checkpoint
from curve_vae.training.data import DataConfig, default_cache, generate_curves, load_or_generate
from curve_vae.training.evaluate import evaluate_set, interpolation_report, onnx_codec
from curve_vae.training.export import export
from curve_vae.training.model import VAE, ModelConfig


def load_weights(path: str, spline_ctrl: int) -> VAE:
    """A model from a shipped vae.pt or a training checkpoint, with the given B-spline head."""
    if Path(path).name == "vae.pt":
        ckpt = torch.load(path, map_location="cpu", weights_only=True)
        cfg, state = ModelConfig(**ckpt["model_config"]), ckpt["model"]
    else:
        trained = model_from_checkpoint(path)
        cfg, state = trained.cfg, trained.state_dict()
    model = VAE(replace(cfg, spline_ctrl=spline_ctrl))
    model.load_state_dict(state)
    return model.eval()


def decoder_ms(model_dir: Path, latent_dim: int, batch: int, repeats: int) -> float:
    opts = ort.SessionOptions()
    opts.intra_op_num_threads = 1
    sess = ort.InferenceSession(str(model_dir / "decoder.onnx"), opts, providers=["CPUExecutionProvider"])
    z = np.random.default_rng(0).standard_normal((batch, latent_dim)).astype(np.float32)
    sess.run(None, {"latent": z})
    best = float("inf")
    for _ in range(3):
        t0 = time.perf_counter()
        for _ in range(repeats):
            sess.run(None, {"latent": z})
        best = min(best, (time.perf_counter() - t0) / repeats / batch * 1e3)
    return best


def airfoil_report(model_dir: Path, airfoils: list[np.ndarray], spline_ctrl: int) -> dict[str, float]:
    runtime = CurveRuntime.load(model_dir, providers="cpu", intra_op_threads=1)
    res = runtime.reconstruct(airfoils, Reading(spacing="arc_length"))
    rec, mse = res.curves, res.mse
    diag = np.array([np.linalg.norm(np.ptp(c, axis=0)) for c in airfoils])
    rel = np.sqrt(2 * mse) / diag  # mse is per coordinate: RMSE of point distances
    lead = np.array([np.linalg.norm(r[np.argmin(c[:, 0])] - c[np.argmin(c[:, 0])]) for r, c in zip(rec, airfoils)])
    out = {
        "rel_rmse_mean": float(rel.mean()),
        "rel_rmse_max": float(rel.max()),
        "leading_edge_rel_error": float((lead / diag).mean()),
        "roughness": float(np.mean([smoothness(r)["roughness"] for r in rec])),
    }
    if spline_ctrl:  # what the basis alone allows: each airfoil (as the model sees it) projected onto it
        x = runtime.prepare(airfoils, spacing="arc_length").model.astype(np.float64)
        basis, pinv = spline_head(spline_ctrl, x.shape[1])
        px = basis @ pinv @ x
        d = np.linalg.norm(np.ptp(x, axis=1), axis=1)
        out["basis_floor_rel_rmse"] = float((np.sqrt(((px - x) ** 2).sum(-1).mean(-1)) / d).mean())
    return out


def measure(model: VAE, name: str, sets: dict[str, np.ndarray], airfoils: list[np.ndarray], model_size: float) -> dict:
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp)
        export(model, out, model_size=model_size, weights=False)
        encode, decode, _ = onnx_codec(out)
        row: dict[str, Any] = {"candidate": name, "spline_ctrl": model.cfg.spline_ctrl}
        for set_name, curves in sets.items():
            recon = np.concatenate([decode(encode(curves[i : i + 500])) for i in range(0, len(curves), 500)])
            r = evaluate_set(curves, recon)
            interp = interpolation_report(encode, decode, curves)
            row[set_name] = {
                "mse": r["mse"],
                "roughness_input": r["smoothness_input"]["roughness"],
                "roughness": r["smoothness_output"]["roughness"],
                "self_intersecting": r["self_intersecting_outputs"],
                "interp_roughness": interp["latent"]["roughness"],
                "interp_self_intersecting": interp["latent"]["self_intersecting"],
                "pointwise_roughness": interp["pointwise"]["roughness"],
                "pointwise_self_intersecting": interp["pointwise"]["self_intersecting"],
            }
        if airfoils:
            row["airfoils"] = airfoil_report(out, airfoils, model.cfg.spline_ctrl)
        row["decoder_ms_per_curve"] = {
            "batch_1": decoder_ms(out, model.cfg.latent_dim, 1, 200),
            "batch_128": decoder_ms(out, model.cfg.latent_dim, 128, 5),
        }
    return row


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--weights", default="models/vae.pt", help="weights the projection heads are put on")
    p.add_argument("--heads", type=int, nargs="*", default=[0, 10, 17, 24, 31], help="control points (0: raw)")
    p.add_argument("--checkpoint", nargs="*", default=[], help="fine-tuned checkpoints, measured with their own head")
    p.add_argument("--airfoils", default="", help="aerosandbox wheel or a directory of .dat files (optional)")
    p.add_argument("--data", default=None, help="the data set cache (default: the configuration's own)")
    p.add_argument("--out", default="", help="write the rows as JSON here")
    a = p.parse_args()
    torch.set_num_threads(2)
    ds = load_or_generate(DataConfig(), a.data or default_cache(DataConfig()))
    sets = {"test": ds.test, "fresh_seed_7919": generate_curves(1000, 7919)[0]}
    airfoils = load_airfoils(a.airfoils) if a.airfoils else []
    size = float(json.loads((Path(a.weights).parent / "manifest.json").read_text())["frame"]["model_size"])
    candidates = [(load_weights(a.weights, k), f"{Path(a.weights).name} + head {k}" if k else "raw") for k in a.heads]
    for ck in a.checkpoint:
        model = model_from_checkpoint(ck)
        candidates.append((model, f"{ck} (head {model.cfg.spline_ctrl}, fine-tuned)"))
    rows = []
    for model, name in candidates:
        rows.append(measure(model, name, sets, airfoils, size))
        print(json.dumps(rows[-1]), flush=True)
    base = rows[0]["decoder_ms_per_curve"]
    print(
        "\n| candidate | MSE test / fresh | roughness rec. | interp. roughness | interp. self-int. | "
        "airfoil rel. RMSE (LE) | basis floor | cost b1 / b128 |"
    )
    print("|---|---|---|---|---|---|---|---|")
    for r in rows:
        t, f = r["test"], r["fresh_seed_7919"]
        air = r.get("airfoils", {})
        cost = r["decoder_ms_per_curve"]
        print(
            f"| {r['candidate']} | {t['mse']:.4f} / {f['mse']:.4f} | {t['roughness']:.3f}° / {f['roughness']:.3f}° | "
            f"{t['interp_roughness']:.3f}° / {f['interp_roughness']:.3f}° | "
            f"{t['interp_self_intersecting']:.1%} / {f['interp_self_intersecting']:.1%} | "
            + (
                f"{air['rel_rmse_mean']:.2%} ({air['leading_edge_rel_error']:.2%}) | "
                f"{air.get('basis_floor_rel_rmse', 0):.3%} | "
                if air
                else "– | – | "
            )
            + f"{cost['batch_1'] / base['batch_1']:.2f}× / {cost['batch_128'] / base['batch_128']:.2f}× |"
        )
    if a.out:
        Path(a.out).write_text(json.dumps(rows, indent=2) + "\n")


if __name__ == "__main__":
    main()
