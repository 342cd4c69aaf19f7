"""`curve-vae sample` and `augment`: torch-free, through the local model's runtime or, with --server, a deployment;
the same output either way (the JSON the endpoints answer, or a .npy file of the curves)."""

from __future__ import annotations

import argparse
import sys
from typing import Any

import numpy as np

from curve_vae.commands.options import (
    add_generate_options,
    add_model_options,
    add_reading_options,
    add_server_option,
    model_runtime,
    reading_fields,
    reading_of,
    server_client,
)
from curve_vae.curvefiles.help import INPUT_HELP
from curve_vae.errors import InvalidInput
from curve_vae.files import refuse_overwrite
from curve_vae.inference.answers import AugmentResponse, SampleResponse
from curve_vae.inference.choices import AugmentMode, Output, choices
from curve_vae.progress import bar, counted, shown


def cmd_sample(a: argparse.Namespace) -> int:
    from curve_vae.curvefiles import write_output
    from curve_vae.inference.generation.sampling import fresh_seed
    from curve_vae.inference.results import sample_body

    refuse_overwrite(a.output, a.force)
    seed = fresh_seed() if a.seed is None else a.seed
    if a.server:  # the same request to a deployment: its body is what this command writes
        with server_client(a) as c:
            kw = {"temperature": a.temperature, "prior": a.prior, "valid": a.valid, "n_points": a.n_points}
            made = c.sample(a.count, seed=seed, **kw, output=a.output_as, metrics=a.metrics or None)
            body = _sample_body_of(made, a.output_as, a.metrics)
            prior, rejected, points = made.prior, made.rejected, made.stacked().shape[1]
    else:
        runtime = model_runtime(a)
        made = runtime.sample(
            a.count, seed=seed, temperature=a.temperature, prior=a.prior, valid=a.valid, n_points=a.n_points
        )
        body = sample_body(made, metrics=a.metrics, output=a.output_as)
        prior, rejected, points = made.prior, made.rejected, made.curves.shape[1]
    write_output(a.output, body, array_key="curves" if "curves" in body else None)
    print(
        f"{a.output}: {a.count} curves of {points} points from the {prior} prior, seed {seed}; "
        f"{rejected} draws rejected and drawn again",
        file=sys.stderr,
    )
    return 0


def _sample_body_of(made: Any, output: str, metrics: bool) -> SampleResponse:
    """A client's Sampled as the JSON body the endpoint answered (and the local command writes)."""
    body = SampleResponse(
        latents=made.latents.tolist(),
        curves=np.asarray(made.curves).tolist(),
        seed=made.seed,
        offset=0,
        prior=made.prior,
        rejected=made.rejected,
        invalid=made.invalid,
    )
    if output == "bspline":
        del body["curves"]
    if metrics:
        body["metrics"] = made.metrics
    if output != "points":
        body["splines"] = made.splines
    return body


def cmd_augment(a: argparse.Namespace) -> int:
    from curve_vae.curvefiles import read_curves, write_output
    from curve_vae.files import write_npy_chunks
    from curve_vae.inference.generation.sampling import fresh_seed

    refuse_overwrite(a.output, a.force)
    reading_fields(a)  # a reading outside its options is named before the seed curves are read
    seeds = read_curves(a.input)
    seed = fresh_seed() if a.seed is None else a.seed
    if a.output.endswith(".npy") and a.metrics:
        raise InvalidInput("--metrics needs a JSON output: a .npy file holds the curves alone")
    with bar(a.count, "augment", enabled=shown(a.no_progress)) as progress:
        if a.server:
            with server_client(a) as c:
                chunks = _remote_chunks(a, c, seeds, seed)
                shape, body = _write_augment(a, chunks, progress, seed, write_npy_chunks)
        else:
            chunks = _local_chunks(a, model_runtime(a), seeds, seed)
            shape, body = _write_augment(a, chunks, progress, seed, write_npy_chunks)
    if body is not None:
        write_output(a.output, body)
    redrawn = f", {body['redrawn']} mixes that crossed themselves drawn again" if body and body["redrawn"] else ""
    print(f"{a.output}: {a.count} new curves of {shape[1]} points ({a.mode}s), seed {seed}{redrawn}", file=sys.stderr)
    return 0


def _local_chunks(a: argparse.Namespace, runtime: Any, seeds: list, seed: int) -> Any:
    """(count, chunks of Augmented): the local model's sequence, batch_size items a chunk."""
    reading = reading_of(a)
    plan = runtime.plan_augment(seeds, mode=a.mode, seed=seed, neighbours=a.neighbours, reading=reading)
    spacing, step = runtime.reading(reading).spacing, runtime.graphs.batch_size
    length = runtime.mix_length(plan.prep, a.n_points)
    stop = a.offset + a.count
    made = (
        runtime.augment(plan, i, min(i + step, stop), n_points=a.n_points, spacing=spacing)
        for i in range(a.offset, stop, step)
    )
    return length, made


def _remote_chunks(a: argparse.Namespace, c: Any, seeds: list, seed: int) -> Any:
    """The same sequence from a server: .npy chunks for a .npy file, JSON pages (with sources and weights) else."""
    fields = {
        "mode": a.mode,
        "neighbours": a.neighbours,
        **reading_fields(a),
        "n_points": a.n_points,
    }
    if a.output.endswith(".npy"):
        made = c.augment_chunks(seeds, a.count, seed=seed, offset=a.offset, chunk=4096, **fields)
    else:
        page = int(c.model()["limits"]["max_curves"])
        made = (
            c.augment(
                seeds, min(page, a.offset + a.count - o), seed=seed, offset=o, metrics=a.metrics or None, **fields
            )
            for o in range(a.offset, a.offset + a.count, page)
        )
    first = next(made, None)
    length = int(first.stacked().shape[1]) if first is not None else a.n_points or 161

    def chained() -> Any:
        if first is not None:
            yield first
            yield from made

    return length, chained()


def _write_augment(a: argparse.Namespace, chunks: Any, progress: Any, seed: int, write_npy: Any) -> tuple:
    """Write the chunks: streamed into a .npy file, or gathered into the JSON body /augment answers."""
    from curve_vae.inference.results import frames_json

    length, made = chunks
    shape = (a.count, length, 2)
    if a.output.endswith(".npy"):  # streamed chunk by chunk: any count in bounded memory
        write_npy(a.output, shape, counted((np.asarray(m.curves) for m in made), progress))
        return shape, None
    parts = []
    for m in made:
        parts.append(m)
        progress.update(len(m.curves))
    body = AugmentResponse(
        curves=[c for m in parts for c in np.asarray(m.curves).tolist()],
        sources=[s for m in parts for s in np.asarray(m.sources).tolist()],
        weights=[w for m in parts for w in np.asarray(m.weights).tolist()],
        frames=_frames(parts, frames_json),
        seed=seed,
        offset=a.offset,
        # mixes that crossed themselves, drawn again (a server's JSON pages say so too)
        redrawn=sum(int(getattr(m, "redrawn", 0) or 0) for m in parts),
        invalid=sum(int(getattr(m, "invalid", 0) or 0) for m in parts),
    )
    if a.metrics:
        body["metrics"] = [x for m in parts for x in (m.metrics or _metrics(m))]
    return shape, body


def _frames(parts: list, frames_json: Any) -> Any:
    """The frames of every part: the runtime's Frames, or a server's JSON frames."""
    if not parts or parts[0].frames is None or parts[0].frames == [] or parts[0].frames[0] is None:
        return None
    if isinstance(parts[0].frames[0], dict):
        return [f for m in parts for f in m.frames]
    return frames_json([f for m in parts for f in m.frames])


def _metrics(made: Any) -> list:
    from curve_vae.inference.results import curve_metrics

    return curve_metrics(made.curves)


def _add_sample(sub: argparse._SubParsersAction) -> None:
    s = sub.add_parser("sample", help="new curves from the latent prior, offline (as POST /sample)")
    add_generate_options(s)
    s.add_argument(
        "--temperature", type=float, default=1.0, help="spread of the latents about the prior's means (default: 1.0)"
    )
    s.add_argument(
        "--prior",
        default=None,
        help="learned: the latent density shipped with the model; standard: N(0, I); or the name of a prior fitted "
        "with `curve-vae prior` (in --priors-dir) (default: learned if shipped)",
    )
    s.add_argument(
        "--valid",
        action=argparse.BooleanOptionalAction,
        default=True,
        help="redraw curves that cross themselves or leave the data's disc (default: on)",
    )
    s.add_argument(
        "--output-as",
        choices=choices(Output),
        default="points",
        help="curves as points, as B-splines (control points, knots, params), or both; .svg and .dxf outputs draw "
        "the B-splines exactly (default: points)",
    )
    s.add_argument("--priors-dir", default="", help="priors fitted with `curve-vae prior`, for --prior NAME")
    add_model_options(s)
    add_server_option(s)
    s.set_defaults(func=cmd_sample)


def _add_augment(sub: argparse._SubParsersAction) -> None:
    s = sub.add_parser("augment", help="new curves between given curves, offline (as POST /augment)")
    s.add_argument("input", help=f"seed {INPUT_HELP}")
    add_generate_options(s)
    s.add_argument("--mode", choices=choices(AugmentMode), default="pair", help="sources per new curve (default: pair)")
    s.add_argument(
        "--neighbours",
        type=int,
        default=None,
        help="mix each curve only with its k nearest in latent space (default: any)",
    )
    s.add_argument("--offset", type=int, default=0, help="index of the first curve in the seeded sequence (default: 0)")
    add_reading_options(s, of="seed curves")
    add_model_options(s)
    add_server_option(s)
    s.set_defaults(func=cmd_augment)


def register(sub: argparse._SubParsersAction) -> None:
    _add_sample(sub)
    _add_augment(sub)
