"""`curve-vae prior` (a latent prior fitted to your own curves) and `evaluate-prior` (its samples against held-out
curves, with the field's metrics). Torch-free; the mixture's fit needs scikit-learn (the `priors` extra)."""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from curve_vae.commands.options import add_model_options, model_runtime
from curve_vae.errors import InvalidInput
from curve_vae.files import refuse_overwrite


def cmd_prior(a: argparse.Namespace) -> int:
    from curve_vae.curvefiles import read_curve_files
    from curve_vae.training.prior import fit_named_prior

    out = Path(a.output)
    if out.suffix != ".npz":
        raise InvalidInput(f"{out}: a prior is a .npz file named after it (NAME.npz: /sample's prior NAME)")
    refuse_overwrite(out, a.force)
    curves = read_curve_files(a.curves)
    if len(curves) < 2:
        raise InvalidInput(f"{a.curves}: {len(curves)} curves; a prior needs at least 2")
    runtime = model_runtime(a)
    prior = fit_named_prior(
        runtime,
        curves,
        name=out.stem,
        kind=a.kind,
        components=a.components,
        refine=a.refine,
        seed=a.seed,
        source=a.curves,
    )
    prior.save(out)
    chose = f"{len(prior.mixture.weights)} components: {prior.meta['chosen_by']}"
    r = prior.meta["reading"]
    print(
        f"{out}: a prior of {len(curves)} curves ({chose}), read with pose {r['pose']}, spacing {r['spacing']}, "
        f"{r['refine']} fitting steps; {'closed' if prior.closed else 'open'} curves; serve it with --priors-dir "
        f"{out.parent} and ask /sample for prior {out.stem!r}",
        file=sys.stderr,
    )
    return 0


def cmd_evaluate_prior(a: argparse.Namespace) -> int:
    from curve_vae.curvefiles import read_curve_files
    from curve_vae.evaluation.prior_report import evaluate_prior, format_report
    from curve_vae.inference.generation.named_priors import NamedPrior

    for path in (a.out, a.figure):  # before the evaluation's minutes, not after
        if path:
            refuse_overwrite(path, a.force)
    builtin = a.prior in ("learned", "standard")
    prior = None if builtin else NamedPrior.load(a.prior)
    name = a.prior if prior is None else prior.name  # a built-in prior's, or the file's
    runtime = model_runtime(a, priors_dir=None if builtin else Path(a.prior).parent)
    held_out = read_curve_files(a.curves)
    if a.train:
        train = read_curve_files(a.train)
    elif prior is not None:  # the prior's own curves, as the model reconstructs them in their frames
        ref = prior.reference
        train = list(runtime.decode(ref.latents, frames=[ref.frame(i) for i in range(len(ref.latents))]).curves)
    else:
        raise InvalidInput(f"--prior {a.prior}: a built-in prior needs --train, the curves it was fitted to")
    report = evaluate_prior(
        runtime,
        name,
        held_out,
        train,
        seeds=list(range(a.seeds)),
        count=a.count,
        points=a.points,
        likelihood_samples=a.likelihood_samples,
        lsc_lines=a.lsc_lines,
    )
    print(format_report(report))
    if a.figure:
        from curve_vae.training.figures import plot_beside

        made = runtime.sample(12, seed=0, prior=name)
        plot_beside(list(made.curves), held_out, Path(a.figure), title=f"prior {report['prior']}, seed 0")
    if a.out:
        Path(a.out).write_text(json.dumps(report, indent=1) + "\n")
    return 0


def register(sub: argparse._SubParsersAction) -> None:
    s = sub.add_parser("prior", help="fit a latent prior to your own curves: /sample makes more like them")
    s.add_argument(
        "--curves", required=True, help="a curve file, or a directory of them (.json, .csv, .npy, .dat, .svg, .dxf, …)"
    )
    s.add_argument("-o", "--output", required=True, help="the prior, NAME.npz (its name is the file's stem)")
    s.add_argument(
        "--kind",
        choices=["parzen", "gmm"],
        default="parzen",
        help="parzen: one component per curve along its neighbours' directions; gmm: a Gaussian mixture whose size "
        "BIC chooses (default: parzen)",
    )
    s.add_argument(
        "--components", type=int, default=None, help="with --kind gmm: components (default: chosen by BIC, 1 to 10)"
    )
    s.add_argument("--refine", type=int, default=10, help="fitting steps on each curve's latent first (default: 10)")
    s.add_argument("--seed", type=int, default=0, help="seed of the mixture's fit (default: 0)")
    add_model_options(s)
    s.set_defaults(func=cmd_prior)
    s = sub.add_parser("evaluate-prior", help="a prior's samples against held-out curves, with the field's metrics")
    s.add_argument(
        "--prior", required=True, help="the prior's file (NAME.npz, from curve-vae prior), or learned / standard"
    )
    s.add_argument("--curves", required=True, help="held-out curves: a file or a directory")
    s.add_argument(
        "--train",
        default="",
        help="the curves the prior was fitted to, for novelty and copy-rate (default: its reference curves as the "
        "model reconstructs them)",
    )
    s.add_argument("--seeds", type=int, default=5, help="seeds: each metric's interval is over them (default: 5)")
    s.add_argument("--count", type=int, default=2000, help="samples per seed (default: 2000, as BézierGAN)")
    s.add_argument("--points", type=int, default=192, help="points per curve, by arc length (default: 192)")
    s.add_argument(
        "--likelihood-samples", type=int, default=500, help="samples the density is fitted to; 0 skips (default: 500)"
    )
    s.add_argument("--lsc-lines", type=int, default=100, help="latent lines of LSC; 0 skips (default: 100)")
    s.add_argument("--out", default="", help="also write the report as JSON here")
    s.add_argument("--figure", default="", help="also draw 12 samples (seed 0) beside 12 held-out curves here, as PNG")
    add_model_options(s)
    s.set_defaults(func=cmd_evaluate_prior)
