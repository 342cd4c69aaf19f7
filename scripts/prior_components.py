"""Which latent density to ship for /sample: Gaussian mixtures of 1 … K components, side by side (one run).

    .venv/bin/python scripts/prior_components.py --model-dir models --components 1 8 32

Each mixture is fitted (training/prior.py) to the latent means of the first 20,000 training
curves and put in place of the model's prior.npz in a scratch copy of the model; 1,000 samples
of each (seed 0) are measured as `curve-vae evaluate` measures the shipped one, every draw
kept: self-intersecting share, share rejected by /sample (self-intersecting or outside the
data's disc), size, roughness, coverage and precision against a second set of real curves.
"""

from __future__ import annotations

import argparse
import json
import shutil
import tempfile
import time
from pathlib import Path

import numpy as np

from curve_vae.inference.generation.prior import PRIOR_FILE
from curve_vae.inference.model.manifest import file_sha256
from curve_vae.inference.runtime import CurveRuntime
from curve_vae.training.data import DataConfig, default_cache, generate_curves, load_or_generate
from curve_vae.training.evaluate import sample_quality
from curve_vae.training.prior import FIT_CURVES, fit_prior


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--model-dir", default="models")
    p.add_argument("--components", type=int, nargs="+", default=[1, 8, 32])
    p.add_argument("--data", default=None, help="the data set cache (default: the configuration's own)")
    a = p.parse_args()
    ds = load_or_generate(DataConfig(), a.data or default_cache(DataConfig()))
    reference = generate_curves(1000, 7919)[0]
    with tempfile.TemporaryDirectory() as tmp:
        scratch = Path(tmp) / "model"
        shutil.copytree(a.model_dir, scratch)
        runtime = CurveRuntime.load(scratch, providers="cpu")
        means, _ = runtime.graphs.encode(ds.train[:FIT_CURVES])
        for k in a.components:
            t0 = time.perf_counter()
            prior = fit_prior(means, components=k)
            seconds = time.perf_counter() - t0
            prior.save(scratch / PRIOR_FILE)
            manifest = json.loads((scratch / "manifest.json").read_text())
            manifest["files"][PRIOR_FILE]["sha256"] = file_sha256(scratch / PRIOR_FILE)
            (scratch / "manifest.json").write_text(json.dumps(manifest))
            rt = CurveRuntime.load(scratch, providers="cpu")
            made = rt.sample(len(reference), seed=0, prior="learned", valid=False)
            q = sample_quality(made.curves, ds.test, reference)
            rejected = 1 - rt.sampler.plausible(made.curves.astype(np.float64)).mean()
            print(
                f"| {k} | {q['self_intersecting']:.1%} | {rejected:.1%} | {q['size_vs_data']:.2f}× | "
                f"{q['roughness']:.3f}° | {q['coverage_vs_real']:.2f}× | {q['precision_vs_real']:.2f}× | "
                f"{seconds:.0f} s |",
                flush=True,
            )


if __name__ == "__main__":
    main()
