"""`curve-vae` command line: dataset, train, average, export, evaluate, sample, augment, fit, revolve, serve.

Each subcommand imports what it needs when it runs, so `curve-vae serve` and the offline
commands (sample, augment, fit, revolve) work in the base install (no torch).

Length (~850 lines): one function per subcommand plus its argparse block, still one module;
issue 20 moves each command beside the code it drives (a `curve_vae/commands/` package).
"""

from __future__ import annotations

import argparse
import json
import os
import sys
from dataclasses import fields
from pathlib import Path
from typing import Any

from curve_vae.files import refuse_overwrite
from curve_vae.progress import bar, counted, shown

DATA_HELP = "data/curves-<digest of the configuration>.npz: one file per configuration"
DEFAULT_MODELS = "models"
FRESH_TEST_SEED = 7919  # the second test set: a seed no training or model selection uses


def _add_data_options(p: argparse.ArgumentParser) -> None:
    g = p.add_argument_group("data set (paper §3.1)")
    g.add_argument(
        "--data",
        default=None,
        help="data set cache file: read when it holds this configuration, written when it does not exist, never "
        f"overwritten (default: {DATA_HELP})",
    )
    g.add_argument("--n-train", type=int, default=70_000, help="training curves (default: 70000)")
    g.add_argument("--n-val", type=int, default=2_000, help="validation curves (default: 2000)")
    g.add_argument("--n-test", type=int, default=1_000, help="test curves (default: 1000)")
    g.add_argument("--data-seed", type=int, default=0, help="seed of the data set (default: 0)")
    g.add_argument(
        "--mix",
        choices=("paper", "broad"),
        default="paper",
        help="training curves: the paper's generator, or the broad mix of training/families.py (any spacing, "
        "other shapes, posed as the service poses curves); the test split is the paper's either way (default: paper)",
    )
    g.add_argument(
        "--curves",
        default=None,
        metavar="PATH",
        help="your own curves instead: a file or a directory of .npy/.csv/.json/.dat files; 10%% of the curves are "
        "held out for validation and 10%% for test, and --n-train posed copies of the rest are trained on",
    )
    g.add_argument(
        "--workers",
        type=int,
        default=len(os.sched_getaffinity(0)),
        help="processes drawing the broad mix: the same curves however many (default: the CPUs available, %(default)s)",
    )


def _data_path(a: argparse.Namespace, config: Any) -> Path:
    """--data, or the default cache file of this data configuration."""
    from training.data import default_cache

    return Path(a.data) if a.data else default_cache(config)


def _data_config(a: argparse.Namespace):
    from training.data import DataConfig

    mix = "files" if a.curves else a.mix
    return DataConfig(
        n_train=a.n_train, n_val=a.n_val, n_test=a.n_test, seed=a.data_seed, mix=mix, source=a.curves or ""
    )


# ------------------------------------------------------------------------------ dataset


def cmd_dataset(a: argparse.Namespace) -> int:
    import time

    from training.data import load_or_generate
    from training.figures import pyplot, save_figure

    if a.preview:
        refuse_overwrite(a.preview, a.force, "--preview")
    t = time.perf_counter()
    path = _data_path(a, _data_config(a))
    ds = load_or_generate(_data_config(a), path, workers=a.workers)
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


# -------------------------------------------------------------------------------- train


def _add_train_options(p: argparse.ArgumentParser) -> None:
    from training.config import SCHEDULES, VARIANTS, TrainConfig

    g = p.add_argument_group("model (paper §3.5)")
    g.add_argument(
        "--variant",
        default="inception",
        help=f"architecture: {', '.join(VARIANTS)} "
        "(cnn6 = inception, the paper's model; cnn1…cnn5: Table 1's ablations) (default: inception)",
    )
    g.add_argument("--latent-dim", type=int, default=32, help="latent size, paper Table 2 (default: 32)")
    g.add_argument(
        "--spline-ctrl",
        type=int,
        default=None,
        help="B-spline output head: project decoded points onto a clamped cubic B-spline with this many "
        "control points, 7k+3 to keep the data's knots (0: raw points) (default: the --init-from or resumed "
        "checkpoint's head, else 0)",
    )
    d = TrainConfig()
    g = p.add_argument_group("training")
    helps = {
        "epochs": "epochs (passes over the training curves)",
        "batch_size": "global batch size, split across DDP processes",
        "lr": "Adam learning rate; the peak rate of the onecycle schedule",
        "schedule": f"learning-rate schedule: {' | '.join(SCHEDULES)}",
        "warmup": "onecycle: fraction of the steps spent warming up",
        "beta": "weight of the KL term",
        "lap_weight": "weight of the Laplacian smoothness term (0: off)",
        "grad_clip": "clip the gradient norm to this (0: off)",
        "patience": "early stopping: epochs without a better validation MSE (0: off)",
        "bf16": "bf16 autocast (fast only with AMX/AVX512-BF16 CPUs or GPUs)",
        "compile": "torch.compile the model",
        "seed": "seed of initialisation, batch order and sampling noise",
        "threads": "torch CPU threads (0: torch's default)",
        "device": "auto | cpu | cuda",
        "train_limit": "use only the first N training curves (0: all)",
        "time_budget": "seconds of training; the schedule follows elapsed training time and the run "
        "stops when it is spent, whatever the throughput (0: off; --epochs stays an upper bound)",
        "snapshots": "keep the weights of the latest N epochs as RUN_DIR/epoch-NNNN.pt, to average them "
        "afterwards with curve-vae average (0: off)",
    }
    for f in fields(TrainConfig):
        flag = "--" + f.name.replace("_", "-")
        default = getattr(d, f.name)
        if isinstance(default, bool):
            g.add_argument(
                flag,
                action=argparse.BooleanOptionalAction,
                default=default,
                help=f"{helps[f.name]} (default: {default})",
            )
        else:
            g.add_argument(flag, type=type(default), default=default, help=f"{helps[f.name]} (default: {default})")


def cmd_train(a: argparse.Namespace) -> int:
    import os

    from training.config import ModelConfig, TrainConfig
    from training.evaluate import run_evaluation, torch_codec
    from training.figures import plot_training
    from training.train import train

    spline_ctrl = a.spline_ctrl
    if spline_ctrl is None:  # keep the head of the weights a run continues from: dropping it would go unnoticed
        start = Path(a.run_dir) / "last.pt" if a.resume and (Path(a.run_dir) / "last.pt").exists() else a.init_from
        spline_ctrl = 0
        if start:
            from training.checkpoint import load_weights

            spline_ctrl = load_weights(start)[0].spline_ctrl
    model_cfg = ModelConfig(variant=a.variant, latent_dim=a.latent_dim, spline_ctrl=spline_ctrl)
    cfg = TrainConfig(**{f.name: getattr(a, f.name) for f in fields(TrainConfig)})
    run_dir = Path(a.run_dir)
    state = train(
        run_dir,
        model_cfg,
        _data_config(a),
        cfg,
        data_cache=_data_path(a, _data_config(a)),
        data_workers=a.workers,
        resume=a.resume,
        progress=shown(a.no_progress),
        stop_after=a.stop_after,
        init_from=a.init_from or None,
    )
    if int(os.environ.get("RANK", "0")) != 0:
        return 0
    print(f"best validation MSE {state.best_val:.4f} at epoch {state.best_epoch}; checkpoints in {run_dir}")
    finished = (
        state.epoch >= cfg.epochs
        or (cfg.patience and state.epoch - state.best_epoch >= cfg.patience)
        or 0 < cfg.time_budget <= state.trained_seconds
    )
    if finished:
        from training.data import load_or_generate

        ds = load_or_generate(_data_config(a), _data_path(a, _data_config(a)))
        enc, dec, _ = torch_codec(run_dir / "best.pt")
        report = run_evaluation(enc, dec, {"test": ds.test}, run_dir, log_path=run_dir / "log.jsonl")
        print(
            f"test MSE (paper eq. 4) {report['test_sets']['test']['mse']:.4f}; "
            f"report {run_dir / 'report.json'}, figures {run_dir}/*.png"
        )
    elif (run_dir / "log.jsonl").exists():
        plot_training(run_dir / "log.jsonl", run_dir / "training.png")
    return 0


# ------------------------------------------------------------------------------- export


def cmd_export(a: argparse.Namespace) -> int:
    from training.checkpoint import load_checkpoint, model_from_checkpoint
    from training.data import DataConfig, generate_curves, load_or_generate
    from training.evaluate import onnx_codec, run_evaluation
    from training.export import export, model_size_of
    from training.io import atomic_write_text

    held = [
        f
        for f in ("manifest.json", "encoder.onnx", "decoder.onnx", "vae.pt", "prior.npz")
        if (Path(a.out) / f).exists()
    ]
    if held and not a.force:
        raise ValueError(
            f"{a.out} already holds a model ({', '.join(held)}) and is left as it is: pass --force to replace it, "
            "or export to a new --out directory"
        )
    ckpt = load_checkpoint(a.checkpoint)
    data_cfg = DataConfig(**{**ckpt["data_config"], "center": tuple(ckpt["data_config"]["center"])})
    if data_cfg.mix == "broad":  # posed at one size, tested on the paper's curves: no training split to draw
        from training.data import paper_test_curves
        from training.families import MODEL_SIZE

        train, test, model_size = None, paper_test_curves(data_cfg)[0], MODEL_SIZE
    else:
        ds = load_or_generate(data_cfg, _data_path(a, data_cfg))
        train, test, model_size = ds.train, ds.test, model_size_of(ds.train)
    model = model_from_checkpoint(a.checkpoint)
    if a.spline_ctrl is not None and a.spline_ctrl != model.cfg.spline_ctrl:
        from dataclasses import replace

        from training.model import VAE

        head = VAE(replace(model.cfg, spline_ctrl=a.spline_ctrl))  # the head has no weights: same state dict
        head.load_state_dict(model.state_dict())
        model = head.eval()
    training: dict[str, Any] = {
        "data": ckpt["data_config"],
        "train": ckpt["train_config"],
        "epochs_run": ckpt["state"]["epoch"],
        "best_epoch": ckpt["state"]["best_epoch"],
        "best_val_mse": ckpt["state"]["best_val"],
    }
    if "averaged" in ckpt:  # made by curve-vae average: which checkpoints, and what it measured
        training["averaged"] = ckpt["averaged"]
    if a.training_info:
        training.update(json.loads(Path(a.training_info).read_text()))
    prior, prior_info = None, None
    if a.prior:
        import numpy as np
        import torch

        from training.prior import FIT_CURVES, fit_prior

        # /sample draws the paper's curves: with the broad mix, the prior is fitted to the paper's training curves
        fit_on = (
            train[:FIT_CURVES]
            if train is not None and data_cfg.mix == "paper"
            else generate_curves(min(FIT_CURVES, data_cfg.n_train), data_cfg.seed, n_points=data_cfg.n_points)[0]
        )
        with torch.no_grad():
            means = np.concatenate(
                [model.encoder(torch.from_numpy(fit_on[i : i + 500]))[0].numpy() for i in range(0, len(fit_on), 500)]
            )
        prior = fit_prior(means, components=a.prior_components)
        prior_info = {"fitted_on": f"latent means of the first {len(fit_on)} training curves of the paper's data set"}
        print(f"fitted a {a.prior_components}-component latent prior to {len(fit_on)} training curves")
    manifest = export(
        model,
        a.out,
        name=a.name,
        version=a.version,
        model_size=model_size,
        extra={"training": training},
        prior=prior,
        prior_info=prior_info,
    )
    print(f"exported {a.checkpoint} → {a.out}/: {', '.join(manifest['files'])}, manifest.json")
    if a.evaluate:
        fresh, _ = generate_curves(1000, a.fresh_seed, n_ctrl=data_cfg.n_ctrl, n_points=data_cfg.n_points)
        from service.runtime import CurveRuntime

        enc, dec, _ = onnx_codec(a.out)
        report = run_evaluation(
            enc,
            dec,
            {"test": test, f"fresh_seed_{a.fresh_seed}": fresh},
            Path(a.out) / "report",
            figures=False,
            runtime=CurveRuntime.load(a.out, providers="cpu"),
            suite_count=a.suite_count,
        )
        manifest["metrics"] = {"measured_with": "onnxruntime CPU on the exported graphs", **report}
        atomic_write_text(Path(a.out) / "manifest.json", json.dumps(manifest, indent=2) + "\n")
        (Path(a.out) / "report" / "report.json").unlink()
        (Path(a.out) / "report").rmdir()
        for name, r in report["test_sets"].items():
            print(f"{name}: MSE {r['mse']:.4f} (median {r['mse_median']:.4f}) over {r['n_curves']} curves")
        if "families" in report:
            from training.suite import format_suite

            print(format_suite(report["families"]))
    return 0


# ------------------------------------------------------------------------------ average


def cmd_average(a: argparse.Namespace) -> int:
    import torch

    from training.average import average_checkpoints
    from training.checkpoint import atomic_save, load_checkpoint
    from training.data import DataConfig, load_or_generate

    if a.threads > 0:
        torch.set_num_threads(a.threads)
    for p in a.checkpoints:
        if not Path(p).is_file():
            raise SystemExit(f"curve-vae average: no checkpoint at {p}")
    refuse_overwrite(a.out, a.force, "--out")
    d = load_checkpoint(a.checkpoints[-1])["data_config"]
    data_cfg = DataConfig(**{**d, "center": tuple(d["center"])})
    ds = load_or_generate(data_cfg, _data_path(a, data_cfg))
    train_curves = ds.train[: a.bn_curves] if a.bn_curves > 0 else None
    ckpt = average_checkpoints(a.checkpoints, train_curves=train_curves, val_curves=ds.val)
    atomic_save(ckpt, Path(a.out))
    print(f"averaged {len(a.checkpoints)} checkpoints → {a.out} (export it with curve-vae export --checkpoint)")
    return 0


# ----------------------------------------------------------------------------- evaluate


def cmd_evaluate(a: argparse.Namespace) -> int:
    from training.data import DataConfig, generate_curves, load_or_generate
    from training.evaluate import onnx_codec, run_evaluation, torch_codec

    runtime = None
    if a.checkpoint:
        enc, dec, meta = torch_codec(a.checkpoint)
        import torch

        data_cfg_d = torch.load(a.checkpoint, map_location="cpu", weights_only=True).get("data_config")  # vae.pt: none
    else:
        from service.runtime import CurveRuntime

        enc, dec, meta = onnx_codec(a.model_dir)
        runtime = CurveRuntime.load(a.model_dir, providers="cpu")
        data_cfg_d = meta.get("training", {}).get("data")
    data_cfg = DataConfig(**{**data_cfg_d, "center": tuple(data_cfg_d["center"])}) if data_cfg_d else DataConfig()
    ds = load_or_generate(data_cfg, _data_path(a, data_cfg))
    sets = {"test": ds.test}
    if a.fresh_seed >= 0:
        sets[f"fresh_seed_{a.fresh_seed}"] = generate_curves(
            1000, a.fresh_seed, n_ctrl=data_cfg.n_ctrl, n_points=data_cfg.n_points
        )[0]
    log = Path(a.checkpoint).parent / "log.jsonl" if a.checkpoint else None
    report = run_evaluation(
        enc, dec, sets, a.out, log_path=log, figures=not a.no_figures, runtime=runtime, suite_count=a.suite_count
    )
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
        from training.suite import format_suite

        print("curve families (relative RMSE: RMSE ÷ bounding-box diagonal, through the service's runtime):")
        print(format_suite(report["families"]))
    print(f"report: {Path(a.out) / 'report.json'}")
    return 0


# ------------------------------------------------------------------- sample, augment


def _add_suite_option(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "--suite-count",
        type=int,
        default=200,
        help="curves per set of the family suite (training/suite.py: the paper's curves moved and respaced, "
        "other families, held-out ones, real airfoils where data/ has aerosandbox's wheel); 0 skips it "
        "(default: 200)",
    )


def _runtime(a: argparse.Namespace):
    from service.runtime import CurveRuntime
    from service.settings import DEFAULT_MODEL_DIR

    model_dir = a.model_dir or DEFAULT_MODEL_DIR
    return CurveRuntime.load(model_dir, providers=a.providers, batch_size=a.batch_size, warm_up=False)


def cmd_sample(a: argparse.Namespace) -> int:
    from curve_vae.files import write_output
    from service.payloads import sample_body, with_output
    from service.runtime import fresh_seed

    refuse_overwrite(a.output, a.force)
    runtime = _runtime(a)
    seed = fresh_seed() if a.seed is None else a.seed
    splines: list | None = [] if a.output_as != "points" else None
    made = runtime.sample(
        a.count,
        seed=seed,
        temperature=a.temperature,
        prior=a.prior,
        valid=a.valid,
        n_points=a.n_points,
        spacing=a.spacing,
        splines=splines,
    )
    body = with_output(sample_body(made, seed, metrics=a.metrics), splines, a.output_as)
    write_output(a.output, body, array_key="curves" if "curves" in body else None)
    print(
        f"{a.output}: {a.count} curves of {made.curves.shape[1]} points from the {made.prior} prior, seed {seed}; "
        f"{made.rejected} draws rejected and drawn again",
        file=sys.stderr,
    )
    return 0


def cmd_augment(a: argparse.Namespace) -> int:
    import numpy as np

    from curve_vae.files import read_curves, write_npy_chunks, write_output
    from service.payloads import augment_body
    from service.runtime import fresh_seed

    refuse_overwrite(a.output, a.force)
    runtime = _runtime(a)
    seed = fresh_seed() if a.seed is None else a.seed
    plan = runtime.plan_augment(
        read_curves(a.input),
        mode=a.mode,
        seed=seed,
        neighbours=a.neighbours,
        frame=a.frame,
        spacing=a.spacing,
        pose=a.pose,
    )
    start, stop = a.offset, a.offset + a.count
    step = runtime.batch_size
    with bar(a.count, "augment", enabled=shown(a.no_progress)) as progress:
        if a.output.endswith(".npy"):  # streamed chunk by chunk: any count in bounded memory
            if a.metrics:
                raise ValueError("--metrics needs a JSON output: a .npy file holds the curves alone")
            shape = (a.count, runtime.mix_length(plan.prep, a.n_points), 2)
            chunks = runtime.augment_chunks(plan, start, stop, n_points=a.n_points, spacing=a.spacing, chunk=step)
            write_npy_chunks(a.output, shape, counted(chunks, progress))
        else:
            parts = []  # chunk by chunk for the bar; a count of 0 still makes one (empty) chunk of the right shapes
            for i in range(start, stop, step) or [start]:
                parts.append(
                    runtime.augment_batch(plan, i, min(i + step, stop), n_points=a.n_points, spacing=a.spacing)
                )
                progress.update(len(parts[-1][0]))
            out, sources, weights = (np.concatenate([p[k] for p in parts]) for k in range(3))
            frames = [f for p in parts for f in p[3]]
            shape = out.shape
            body = augment_body(out, sources, weights, frames, seed=seed, offset=a.offset, metrics=a.metrics)
            write_output(a.output, body)
    print(f"{a.output}: {a.count} new curves of {shape[1]} points ({a.mode}s), seed {seed}", file=sys.stderr)
    return 0


def _add_model_options(p: argparse.ArgumentParser) -> None:
    g = p.add_argument_group("model (offline: onnxruntime on the exported graphs, no server)")
    g.add_argument("--model-dir", default="", help="exported model directory (default: the shipped model, models/)")
    g.add_argument(
        "--providers", choices=["cpu", "cuda", "auto"], default="cpu", help="onnxruntime providers (default: cpu)"
    )
    g.add_argument("--batch-size", type=int, default=64, help="curves per ONNX run and per .npy chunk (default: 64)")


def _add_generate_options(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "-o",
        "--output",
        default="-",
        help="output: .json (as the REST endpoint answers), .npy (curves only, float32), "
        "or - for JSON on stdout (default: -)",
    )
    p.add_argument("--count", type=int, required=True, help="how many curves")
    p.add_argument(
        "--seed", type=int, default=None, help="seed: the same seed gives the same curves (default: fresh, reported)"
    )
    p.add_argument(
        "--n-points", type=int, default=None, help="points per curve (default: the model's 161, or the inputs' length)"
    )
    p.add_argument(
        "--spacing", choices=["parameter", "arc_length"], default="parameter", help="point spacing (default: parameter)"
    )
    p.add_argument(
        "--metrics", action="store_true", help="add smoothness, self-intersection and length per curve (JSON only)"
    )
    p.add_argument("--no-progress", action="store_true", help="no progress bar (none either when not on a terminal)")


# ------------------------------------------------------------------------ fit, revolve


def cmd_fit(a: argparse.Namespace) -> int:
    from curve_vae.files import read_curves, write_output
    from service.payloads import fit_body

    refuse_overwrite(a.output, a.force)
    body = fit_body(read_curves(a.input), a.n_ctrl, param=a.param, n_points=a.n_points, tolerance=a.tolerance)
    write_output(a.output, body)
    for i, f in enumerate(body["fits"]):
        print(
            f"curve {i}: {f['n_ctrl']} control points, rms error {f['rms_error']:.4g}, max {f['max_error']:.4g}",
            file=sys.stderr,
        )
    return 0


def cmd_revolve(a: argparse.Namespace) -> int:
    from curve_vae.files import read_curves
    from geometry import revolve
    from training.io import atomic_path

    refuse_overwrite(a.output, a.force)
    curves = read_curves(a.input)
    if len(curves) != 1:
        raise ValueError(f"{a.input}: revolve takes one profile curve, got {len(curves)}")
    mesh = revolve(curves[0], segments=a.segments, axis=a.axis, axis_position=a.axis_position)
    fmt = a.format or ("stl" if a.output.endswith(".stl") else "obj")
    with atomic_path(a.output) as tmp:
        if fmt == "stl":
            tmp.write_bytes(mesh.to_stl())
        else:
            tmp.write_text(mesh.to_obj(comment=f"curve-vae revolve: {len(curves[0])}-point profile"))
    print(f"{a.output}: {len(mesh.vertices)} vertices, {len(mesh.faces)} triangles ({fmt})", file=sys.stderr)
    return 0


def cmd_triton(a: argparse.Namespace) -> int:
    from curve_vae.triton import smoke_test, write_repository
    from service.settings import DEFAULT_MODEL_DIR

    folders = write_repository(
        a.model_dir or DEFAULT_MODEL_DIR,
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


# -------------------------------------------------------------------------------- main


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="curve-vae", description=__doc__.splitlines()[0], formatter_class=argparse.ArgumentDefaultsHelpFormatter
    )
    sub = p.add_subparsers(dest="command", required=True, metavar="COMMAND")

    s = sub.add_parser("dataset", help="generate (or check) the cached curve data set")
    _add_data_options(s)
    s.add_argument("--preview", default="", help="also write a PNG grid of training curves to this path")
    s.set_defaults(func=cmd_dataset)

    s = sub.add_parser("train", help="train a VAE (resumable; DDP under torchrun)")
    s.add_argument(
        "--run-dir", default="runs/default", help="checkpoints, log and report go here (default: runs/default)"
    )
    s.add_argument("--resume", action="store_true", help="continue from RUN_DIR/last.pt if it exists")
    s.add_argument(
        "--stop-after",
        type=int,
        default=0,
        help="stop after this many epochs of this call; resume later (default: 0 = run to --epochs)",
    )
    s.add_argument(
        "--no-progress",
        action="store_true",
        help="no progress bar (none either when stderr is not a terminal); one line per epoch",
    )
    s.add_argument(
        "--init-from",
        default="",
        help="start a new run from these weights (a checkpoint, or models/vae.pt to continue the shipped model)",
    )
    _add_data_options(s)
    _add_train_options(s)
    s.set_defaults(func=cmd_train)

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
        "--evaluate",
        action=argparse.BooleanOptionalAction,
        default=True,
        help="measure the exported graphs on both test sets and store the metrics in the manifest (default: on)",
    )
    _add_suite_option(s)
    s.set_defaults(func=cmd_export)

    s = sub.add_parser(
        "average", help="average the weights of checkpoints and re-measure BatchNorm statistics (SWA-style)"
    )
    s.add_argument("checkpoints", nargs="+", help="training checkpoints of one run (e.g. best.pt last.pt)")
    s.add_argument("--out", required=True, help="the averaged checkpoint (training format, for export)")
    s.add_argument(
        "--data", default=None, help=f"data set cache of the checkpoints' data config (default: {DATA_HELP})"
    )
    s.add_argument(
        "--bn-curves",
        type=int,
        default=20_000,
        help="training curves to measure BatchNorm statistics on; 0 keeps the averaged ones (default: 20000)",
    )
    s.add_argument("--threads", type=int, default=0, help="torch threads (0: torch's default)")
    s.set_defaults(func=cmd_average)

    s = sub.add_parser("evaluate", help="reconstruction MSE, smoothness and figures on the test sets")
    src = s.add_mutually_exclusive_group()
    src.add_argument(
        "--model-dir",
        default=DEFAULT_MODELS,
        help=f"exported model to evaluate with onnxruntime (default: {DEFAULT_MODELS})",
    )
    src.add_argument("--checkpoint", default="", help="evaluate a torch checkpoint instead")
    s.add_argument("--data", default=None, help=f"data set cache (default: {DATA_HELP})")
    s.add_argument(
        "--fresh-seed",
        type=int,
        default=FRESH_TEST_SEED,
        help=f"also test on 1000 curves of this seed, -1 to skip (default: {FRESH_TEST_SEED})",
    )
    s.add_argument(
        "--out", default="runs/evaluation", help="report.json and figures go here (default: runs/evaluation)"
    )
    s.add_argument("--no-figures", action="store_true", help="write only report.json")
    _add_suite_option(s)
    s.set_defaults(func=cmd_evaluate)

    s = sub.add_parser("sample", help="new curves from the latent prior, offline (as POST /sample)")
    _add_generate_options(s)
    s.add_argument(
        "--temperature", type=float, default=1.0, help="spread of the latents about the prior's means (default: 1.0)"
    )
    s.add_argument(
        "--prior",
        choices=["learned", "standard"],
        default=None,
        help="learned: the latent density shipped with the model; standard: N(0, I) (default: learned if shipped)",
    )
    s.add_argument(
        "--valid",
        action=argparse.BooleanOptionalAction,
        default=True,
        help="redraw curves that cross themselves or leave the data's disc (default: on)",
    )
    s.add_argument(
        "--output-as",
        choices=["points", "bspline", "both"],
        default="points",
        help="curves as points, as B-splines (control points, knots, params), or both; JSON only (default: points)",
    )
    _add_model_options(s)
    s.set_defaults(func=cmd_sample)

    s = sub.add_parser("augment", help="new curves between given curves, offline (as POST /augment)")
    s.add_argument("input", help="seed curves: .json ([curve, …] or {curves: …}), .npy (N, n, 2), or - (stdin)")
    _add_generate_options(s)
    s.add_argument("--mode", choices=["pair", "triplet"], default="pair", help="sources per new curve (default: pair)")
    s.add_argument(
        "--neighbours",
        type=int,
        default=None,
        help="mix each curve only with its k nearest in latent space (default: any)",
    )
    s.add_argument("--offset", type=int, default=0, help="index of the first curve in the seeded sequence (default: 0)")
    s.add_argument(
        "--frame", choices=["auto", "model"], default="auto", help="frame of the seed curves (default: auto)"
    )
    s.add_argument(
        "--pose",
        choices=["auto", "as_is"],
        default="auto",
        help="auto: each seed curve is encoded in the pose (turn, mirror, direction) it reconstructs best in, and "
        "new curves come back in their sources' poses; as_is: as oriented (default: auto)",
    )
    _add_model_options(s)
    s.set_defaults(func=cmd_augment)

    s = sub.add_parser("fit", help="least-squares cubic B-spline of each curve (no model needed)")
    s.add_argument("input", help="curves: .json ([[x, y], …], a list of curves, or {curves: …}), .npy, or - (stdin)")
    s.add_argument("-o", "--output", default="-", help="JSON output file (default: - = stdout)")
    s.add_argument(
        "--n-ctrl",
        type=int,
        default=None,
        help="control points (default: the fewest, from 4 up, whose RMS error is within --tolerance)",
    )
    s.add_argument(
        "--tolerance",
        type=float,
        default=1e-3,
        help="without --n-ctrl: RMS fit error to reach, as a fraction of the bounding-box diagonal (default: 0.001)",
    )
    s.add_argument(
        "--param",
        choices=["uniform", "chord"],
        default="chord",
        help="parameter of each point: chord length (any curve) or uniform (the "
        "data set's sampling; recovers its B-splines exactly) (default: chord)",
    )
    s.add_argument("--n-points", type=int, default=None, help="also write each fitted spline at this many points")
    s.set_defaults(func=cmd_fit)

    s = sub.add_parser("revolve", help="surface of revolution of a profile curve, as OBJ or STL (paper Fig. 12)")
    s.add_argument("input", help="one profile curve: .json, .npy, or - (stdin)")
    s.add_argument("-o", "--output", required=True, help="mesh file (.obj or .stl)")
    s.add_argument("--format", choices=["obj", "stl"], default="", help="default: from the file name")
    s.add_argument("--segments", type=int, default=64, help="angular resolution (default: 64)")
    s.add_argument(
        "--axis", choices=["x", "y"], default="y", help="revolve about a vertical (y) or horizontal (x) line"
    )
    s.add_argument(
        "--axis-position",
        type=float,
        default=None,
        help="where that line is (default: through the profile's nearest point)",
    )
    s.set_defaults(func=cmd_revolve)

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

    s = sub.add_parser("serve", help="run the REST service on a model directory")
    try:
        from service.cli import configure_parser, run
    except ImportError as e:  # the service's dependencies are part of the base install
        reason = str(e)
        s.set_defaults(func=lambda _a: sys.exit(f"curve-vae serve is unavailable: {reason}"))
    else:
        configure_parser(s)
        s.set_defaults(func=run)
    for name, what in [
        ("dataset", "the --preview image"),
        ("export", "the model files in --out (the shipped model too)"),
        ("average", "the --out checkpoint"),
        ("sample", "the output file"),
        ("augment", "the output file"),
        ("fit", "the output file"),
        ("revolve", "the output file"),
    ]:
        sub.choices[name].add_argument("--force", action="store_true", help=f"replace {what} if it exists")
    return p


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    try:
        return int(args.func(args) or 0)
    except (ValueError, FileNotFoundError, RuntimeError) as e:
        print(f"curve-vae {args.command}: error: {e}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
