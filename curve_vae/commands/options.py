"""Options and helpers shared by several `curve-vae` commands: the data set's, the model directory's, the suite's."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

from curve_vae.curvefiles.help import OUTPUT_HELP
from curve_vae.errors import InvalidInput
from curve_vae.inference.choices import Providers, choices
from curve_vae.inference.model.cpus import available_cpus
from curve_vae.inference.reading import Reading, reading_options
from curve_vae.training.mixes import MIX_VERSION, MIXES

DATA_HELP = "data/curves-<digest of the configuration>.npz: one file per configuration"
DEFAULT_MODELS = "models"
FRESH_TEST_SEED = 7919  # the second test set: a seed no training or model selection uses
FRESH_TEST_COUNT = 1000  # its curves


def add_data_options(p: argparse.ArgumentParser) -> None:
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
        "--mix-version",
        type=int,
        choices=sorted(MIXES),
        default=0,
        help="with --mix broad: the mix's version (training/families.py MIXES; 2 drew model 0.9.0's curves) "
        f"(default: the latest, {MIX_VERSION})",
    )
    g.add_argument(
        "--curves",
        default=None,
        metavar="PATH",
        help="your own curves instead: a curve file or a directory of them (.json, .csv, .npy, .dat, .svg, .dxf, …); "
        "10%% of the curves are "
        "held out for validation and 10%% for test, and --n-train posed copies of the rest are trained on",
    )
    g.add_argument(
        "--workers",
        type=int,
        default=available_cpus(),
        help="processes drawing the broad mix: the same curves however many (default: the CPUs available, %(default)s)",
    )


def data_path(a: argparse.Namespace, config: Any) -> Path:
    """--data, or the default cache file of this data configuration."""
    from curve_vae.training.data import default_cache

    return Path(a.data) if a.data else default_cache(config)


def data_config(a: argparse.Namespace):
    from curve_vae.training.config import TWIN_MATCHES
    from curve_vae.training.data import DataConfig

    mix = "files" if a.curves else a.mix
    if a.mix_version and mix != "broad":
        raise InvalidInput("--mix-version goes with --mix broad")
    return DataConfig(
        n_train=a.n_train,
        n_val=a.n_val,
        n_test=a.n_test,
        seed=a.data_seed,
        mix=mix,
        source=a.curves or "",
        mix_version=a.mix_version if mix == "broad" else 0,
        twins=getattr(a, "match", "") in TWIN_MATCHES,  # these matches learn from each curve beside its twin
    )


def add_suite_option(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "--suite-count",
        type=int,
        default=200,
        help="curves per set of the family suite (training/suite.py: the paper's curves moved and respaced, "
        "other families, held-out ones, real airfoils where data/ has aerosandbox's wheel); 0 skips it "
        "(default: 200)",
    )


def add_morph_option(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "--morph-count",
        type=int,
        default=40,
        help="pairs of the morph suite (training/morphs.py: sweeps between pairs of the paper's curves drawn in one "
        "pose, their chords' turn and end points' drift beside point-wise blending); 0 skips it (default: 40)",
    )


def add_model_options(p: argparse.ArgumentParser) -> None:
    g = p.add_argument_group("model (offline: onnxruntime on the exported graphs, no server)")
    g.add_argument(
        "--model-dir",
        "--model",
        default="",
        help="exported model directory, or a shipped model's name: default, paper (default: the shipped default)",
    )
    g.add_argument(
        "--providers", choices=choices(Providers), default="cpu", help="onnxruntime providers (default: cpu)"
    )
    g.add_argument("--batch-size", type=int, default=64, help="curves per ONNX run and per .npy chunk (default: 64)")


def add_generate_options(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "-o",
        "--output",
        default="-",
        help=f"{OUTPUT_HELP} (default: -)",
    )
    p.add_argument("--count", type=int, required=True, help="how many curves")
    p.add_argument(
        "--seed", type=int, default=None, help="seed: the same seed gives the same curves (default: fresh, reported)"
    )
    p.add_argument(
        "--n-points", type=int, default=None, help="points per curve (default: the model's 161, or the inputs' length)"
    )
    p.add_argument(
        "--metrics", action="store_true", help="add smoothness, self-intersection and length per curve (JSON only)"
    )
    p.add_argument("--no-progress", action="store_true", help="no progress bar (none either when not on a terminal)")


def add_reading_options(p: argparse.ArgumentParser, *, of: str = "curves") -> None:
    """--frame, --pose, --spacing, --refine: one flag per option of inference.reading.Reading, its values, default
    and help taken from there."""
    g = p.add_argument_group(f"reading (how the {of} are read into the model, as the service's fields)")
    for o in reading_options():
        kind: dict[str, Any] = {"choices": o.values} if o.values else {"type": int}
        g.add_argument(f"--{o.name}", default=o.default, help=f"{o.doc.summary} (default: {o.default})", **kind)


def reading_of(a: argparse.Namespace) -> Reading:
    """The reading the flags of add_reading_options ask for."""
    return Reading(**reading_fields(a))


def reading_fields(a: argparse.Namespace) -> dict[str, Any]:
    """The same as the client's (and the service's) fields, checked: {"frame": …, "pose": …, …}."""
    fields = {o.name: getattr(a, o.name) for o in reading_options()}
    Reading(**fields)  # an out-of-range --refine is named here, before any file is read or server called
    return fields


def model_runtime(a: argparse.Namespace, priors_dir: Path | None = None):
    from curve_vae.inference.model.cpus import limit_blas_threads
    from curve_vae.inference.model.shipped import model_directory
    from curve_vae.inference.runtime import CurveRuntime

    model_dir = model_directory(a.model_dir)
    flag: str | None = getattr(a, "priors_dir", "") or None  # --priors-dir, where the command has it
    priors = priors_dir or flag
    runtime = CurveRuntime.load(
        model_dir, providers=a.providers, batch_size=a.batch_size, warm_up=False, priors_dir=priors
    )
    # numpy's BLAS on one thread, as a Ray job's actors run it: more threads only cost CPU on the reading's small
    # products (inference/model/cpus.py), and their float32 rounding differs, which can tip a near-tie between two
    # readings
    # of a curve, so that a command and a Ray job of the same curves would not write the same answer
    limit_blas_threads(1)
    return runtime


def add_server_option(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "--server",
        default="",
        metavar="URL",
        help="run against a curve-vae service at URL instead of the local model (the same output; an API key from "
        "CURVE_VAE_API_KEY) (default: the local model)",
    )


def server_client(a: argparse.Namespace):
    """A client of --server, with the key of CURVE_VAE_API_KEY."""
    import os

    from curve_vae.client import Client

    return Client(a.server, api_key=os.environ.get("CURVE_VAE_API_KEY") or None)
