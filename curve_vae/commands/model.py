"""`curve-vae export`, `evaluate` and `triton`: a checkpoint into the service's model files (training/export.py), their
measurement (training/evaluate.py, training/suite.py), and a Triton model repository of them (service/triton.py)."""

from __future__ import annotations

import argparse
from pathlib import Path

from curve_vae.commands.options import (
    DATA_HELP,
    DEFAULT_MODELS,
    FRESH_TEST_COUNT,
    FRESH_TEST_SEED,
    add_morph_option,
    add_suite_option,
    data_path,
)
from curve_vae.errors import InvalidInput
from curve_vae.inference.choices import SplinePlacement, choices


def cmd_export(a: argparse.Namespace) -> int:
    from curve_vae.training.export import export_checkpoint, measure_export

    held = [
        f
        for f in ("manifest.json", "encoder.onnx", "decoder.onnx", "vae.pt", "prior.npz")
        if (Path(a.out) / f).exists()
    ]
    if held and not a.force:
        raise InvalidInput(
            f"{a.out} already holds a model ({', '.join(held)}) and is left as it is: pass --force to replace it, "
            "or export to a new --out directory"
        )
    manifest, data_cfg, test = export_checkpoint(
        a.checkpoint,
        a.out,
        name=a.name,
        version=a.version,
        data_cache=a.data,
        spline_ctrl=a.spline_ctrl,
        placement=a.placement,
        training_info=a.training_info or None,
        prior_components=a.prior_components if a.prior else 0,
    )
    print(f"exported {a.checkpoint} → {a.out}/: {', '.join(manifest.files)}, manifest.json")
    if a.evaluate:
        report = measure_export(
            a.out,
            manifest,
            data_cfg,
            test,
            fresh_seed=a.fresh_seed,
            fresh_count=a.fresh_count,
            suite_count=a.suite_count,
        )
        for name, r in report["test_sets"].items():
            print(f"{name}: MSE {r['mse']:.4f} (median {r['mse_median']:.4f}) over {r['n_curves']} curves")
        if "families" in report:
            from curve_vae.training.suite import format_suite

            print(format_suite(report["families"]))
    return 0


def cmd_evaluate(a: argparse.Namespace) -> int:
    from curve_vae.training.data import DataConfig, generate_curves, load_test_split
    from curve_vae.training.evaluate import run_evaluation, runtime_codec, torch_codec

    runtime = None
    if a.checkpoint:
        enc, dec, meta = torch_codec(a.checkpoint)
        import torch

        data_cfg_d = torch.load(a.checkpoint, map_location="cpu", weights_only=True).get("data_config")  # vae.pt: none
    else:
        from curve_vae.inference.runtime import CurveRuntime

        runtime = CurveRuntime.load(a.model_dir, providers="cpu")
        enc, dec, meta = runtime_codec(runtime)
        data_cfg_d = meta.get("training", {}).get("data")
    data_cfg = DataConfig(**{**data_cfg_d, "center": tuple(data_cfg_d["center"])}) if data_cfg_d else DataConfig()
    sets = {"test": load_test_split(data_cfg, data_path(a, data_cfg))}
    if a.fresh_seed >= 0:
        sets[f"fresh_seed_{a.fresh_seed}"] = generate_curves(
            a.fresh_count, a.fresh_seed, n_ctrl=data_cfg.n_ctrl, n_points=data_cfg.n_points
        )[0]
    log = Path(a.checkpoint).parent / "log.jsonl" if a.checkpoint else None
    report = run_evaluation(
        enc,
        dec,
        sets,
        a.out,
        log_path=log,
        figures=not a.no_figures,
        runtime=runtime,
        suite_count=a.suite_count,
        suite_refine=a.suite_refine,
        morph_count=a.morph_count,
    )
    _print_test_sets(report)
    _print_measures(report)
    print(f"report: {Path(a.out) / 'report.json'}")
    return 0


def _print_test_sets(report: dict) -> None:
    """Each test set's eq. 4 MSE, smoothness and interpolants, a line or two each."""
    for name, r in report["test_sets"].items():
        s_in, s_out = r["smoothness_input"]["roughness"], r["smoothness_output"]["roughness"]
        print(
            f"{name}: MSE {r['mse']:.4f} (paper eq. 4, {r['n_curves']} curves; median {r['mse_median']:.4f}); "
            f"roughness in {s_in:.3f}° out {s_out:.3f}°; self-intersecting outputs {r['self_intersecting_outputs']:.1%}"
        )
        if "interpolation" not in r:
            continue
        lat, pw = r["interpolation"]["latent"], r["interpolation"]["pointwise"]
        print(
            f"  interpolants ({r['interpolation']['pairs']} pairs): latent roughness {lat['roughness']:.3f}°, "
            f"self-intersecting {lat['self_intersecting']:.1%}; point-wise blends {pw['roughness']:.3f}°, "
            f"{pw['self_intersecting']:.1%}"
        )


def _print_measures(report: dict) -> None:
    """The morph suite, the priors' samples and the family suite, where the report has them."""
    if "morphs" in report:
        from curve_vae.training.morphs import format_morphs

        print(f"morph suite ({report['morphs']['pairs']} pairs, {report['morphs']['steps']} steps):")
        print(format_morphs(report["morphs"]))
    for prior, g in report.get("generation", {}).items():
        if isinstance(g, dict):
            raw, kept = g["every_draw"], g["valid"]
            print(
                f"samples, {prior} prior: {raw['self_intersecting']:.1%} self-intersecting before rejection "
                f"({kept['rejected_share']:.1%} of draws rejected); size {kept['size_vs_data']:.2f}× the data's, "
                f"roughness {kept['roughness']:.3f}°, coverage {kept['coverage_vs_real']:.2f}×, "
                f"precision {kept['precision_vs_real']:.2f}× of real curves'"
            )
    if "families" in report:
        from curve_vae.training.suite import format_suite

        print("curve families (relative RMSE: RMSE ÷ bounding-box diagonal, through the service's runtime):")
        print(format_suite(report["families"]))
        if "families_refined" in report:
            print(f"the same, refined (request option refine: {report['families_refined']['refine']}):")
            print(format_suite(report["families_refined"]["sets"]))


def cmd_triton(a: argparse.Namespace) -> int:
    from curve_vae.inference.model.shipped import model_directory
    from curve_vae.triton import smoke_test, write_repository

    folders = write_repository(
        model_directory(a.model_dir),
        a.out,
        prefix=a.prefix,
        max_batch_size=a.max_batch_size,
        max_queue_delay_us=a.max_queue_delay_us,
        force=a.force,
    )
    for folder in folders:
        shapes = ", ".join(f"{k} {list(v)}" for k, v in smoke_test(folder).items())
        print(f"{folder}: config.pbtxt, 1/model.onnx (a batch of 3 runs: {shapes})")
    return 0


def _add_fresh_count(s: argparse.ArgumentParser) -> None:
    s.add_argument(
        "--fresh-count",
        type=_positive_int,
        default=FRESH_TEST_COUNT,
        help=f"curves of the second test set; its samples' report draws as many (default: {FRESH_TEST_COUNT})",
    )


def _positive_int(text: str) -> int:
    value = int(text)
    if value < 1:
        raise argparse.ArgumentTypeError(f"must be at least 1, got {value}")
    return value


def _add_export(sub: argparse._SubParsersAction) -> None:
    s = sub.add_parser("export", help="export a checkpoint to ONNX + manifest (the service's model)")
    s.add_argument("--checkpoint", required=True, help="a training checkpoint (best.pt / last.pt)")
    s.add_argument("--out", default=DEFAULT_MODELS, help=f"output directory (default: {DEFAULT_MODELS})")
    s.add_argument("--name", default="curve-vae-inception", help="model name in the manifest")
    s.add_argument("--version", default="0.1.0", help="model version in the manifest")
    s.add_argument(
        "--data", default=None, help=f"data set cache of the checkpoint's data config (default: {DATA_HELP})"
    )
    s.add_argument(
        "--fresh-seed",
        type=int,
        default=FRESH_TEST_SEED,
        help=f"seed of the second test set (default: {FRESH_TEST_SEED})",
    )
    _add_fresh_count(s)
    s.add_argument(
        "--training-info",
        default="",
        help="JSON file merged into the manifest's training section (wall time, hardware)",
    )
    s.add_argument(
        "--prior",
        action=argparse.BooleanOptionalAction,
        default=True,
        help="fit the learned latent distribution /sample draws from and ship it as prior.npz (default: on)",
    )
    s.add_argument("--prior-components", type=int, default=8, help="Gaussian mixture components (default: 8)")
    s.add_argument(
        "--spline-ctrl",
        type=int,
        default=None,
        help="export with this B-spline output head (control points, 0: none) in place of the checkpoint's; "
        "the head has no weights, so any checkpoint takes any head (default: the checkpoint's)",
    )
    s.add_argument(
        "--placement",
        choices=choices(SplinePlacement),
        default="closest",
        help="with a B-spline head, how the service places a reconstruction's points, recorded in the manifest: "
        "closest (each input point at its closest point on the decoded spline: never further from the input than "
        "the model's own points on that spline) or "
        "index (point i at the head's parameter i, as models before 0.10.1 were served) (default: closest)",
    )
    s.add_argument(
        "--evaluate",
        action=argparse.BooleanOptionalAction,
        default=True,
        help="measure the exported graphs on both test sets and store the metrics in the manifest (default: on)",
    )
    add_suite_option(s)
    s.set_defaults(func=cmd_export)


def _add_evaluate(sub: argparse._SubParsersAction) -> None:
    s = sub.add_parser("evaluate", help="reconstruction MSE, smoothness and figures on the test sets")
    src = s.add_mutually_exclusive_group()
    src.add_argument(
        "--model-dir",
        default=DEFAULT_MODELS,
        help=f"exported model to evaluate with onnxruntime (default: {DEFAULT_MODELS})",
    )
    src.add_argument("--checkpoint", default="", help="evaluate a torch checkpoint instead")
    s.add_argument(
        "--suite-refine",
        type=int,
        default=0,
        help="also measure the family suite with this many fitting steps (the request option refine; about 8× "
        "the time at 10 steps); needs --model-dir and --suite-count > 0 (default: 0, not measured)",
    )
    s.add_argument("--data", default=None, help=f"data set cache (default: {DATA_HELP})")
    s.add_argument(
        "--fresh-seed",
        type=int,
        default=FRESH_TEST_SEED,
        help=f"also test on --fresh-count curves of this seed, -1 to skip (default: {FRESH_TEST_SEED})",
    )
    _add_fresh_count(s)
    s.add_argument(
        "--out", default="runs/evaluation", help="report.json and figures go here (default: runs/evaluation)"
    )
    s.add_argument("--no-figures", action="store_true", help="write only report.json")
    add_suite_option(s)
    add_morph_option(s)
    s.set_defaults(func=cmd_evaluate)


def _add_triton(sub: argparse._SubParsersAction) -> None:
    s = sub.add_parser("triton", help="write an NVIDIA Triton model repository of an exported model's graphs")
    s.add_argument("--model-dir", default="", help="exported model directory (default: the shipped model, models/)")
    s.add_argument("--out", required=True, help="the repository directory (model folders are created in it)")
    s.add_argument("--prefix", default="curve_vae", help="model name prefix: PREFIX_encoder, PREFIX_decoder")
    s.add_argument("--max-batch-size", type=int, default=256, help="Triton's max_batch_size (default: 256)")
    s.add_argument(
        "--max-queue-delay-us", type=int, default=2000, help="dynamic batching queue delay (default: 2000 µs)"
    )
    s.add_argument("--force", action="store_true", help="replace model folders that exist")
    s.set_defaults(func=cmd_triton)


def cmd_warm_up(a: argparse.Namespace) -> None:
    """Compile the reading's kernels into numba's cache, as a first start of the service would."""
    import time

    from curve_vae.inference.model.opening import compiled_kernels
    from curve_vae.inference.model.shipped import model_directory
    from curve_vae.inference.runtime import CurveRuntime

    where, missing = compiled_kernels()
    start = time.perf_counter()
    CurveRuntime.load(model_directory(a.model_dir), providers="cpu", cache_bytes=0)
    what = f"compiled {', '.join(missing)} into" if missing else "found every kernel compiled already in"
    print(f"curve-vae warm-up: {what} {where} ({time.perf_counter() - start:.1f} s)")


def _add_warm_up(sub: argparse._SubParsersAction) -> None:
    s = sub.add_parser(
        "warm-up",
        help="compile the reading's kernels into numba's cache (NUMBA_CACHE_DIR), as the service's first start does: "
        "at an image's build, so that its containers start warm (CURVE_VAE_KERNEL_CACHE_SEED; docs/DEPLOYMENT.md)",
    )
    s.add_argument("--model-dir", default="", help="exported model directory (default: the shipped model, models/)")
    s.set_defaults(func=cmd_warm_up)


def register(sub: argparse._SubParsersAction) -> None:
    _add_export(sub)
    _add_evaluate(sub)
    _add_triton(sub)
    _add_warm_up(sub)
