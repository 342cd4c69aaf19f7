"""`curve-vae sample`, `augment`, `fit` and `revolve`: offline and torch-free, through the service's runtime."""

from __future__ import annotations

import argparse
import sys

from curve_vae.commands.options import (
    add_generate_options,
    add_model_options,
    model_runtime,
)
from curve_vae.files import refuse_overwrite
from curve_vae.inference.choices import AugmentMode, Axis, FitParam, FrameMode, MeshFormat, Output, Pose, choices
from curve_vae.progress import bar, counted, shown


def cmd_sample(a: argparse.Namespace) -> int:
    from curve_vae.files import write_output
    from curve_vae.inference.bodies import sample_body, with_output
    from curve_vae.inference.sampling import fresh_seed

    refuse_overwrite(a.output, a.force)
    runtime = model_runtime(a)
    seed = fresh_seed() if a.seed is None else a.seed
    made = runtime.sample(
        a.count, seed=seed, temperature=a.temperature, prior=a.prior, valid=a.valid, n_points=a.n_points
    )
    body = with_output(sample_body(made, metrics=a.metrics), made.splines, a.output_as)
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
    from curve_vae.inference.bodies import augment_body
    from curve_vae.inference.reading import Reading
    from curve_vae.inference.results import Augmented
    from curve_vae.inference.sampling import fresh_seed

    refuse_overwrite(a.output, a.force)
    runtime = model_runtime(a)
    seed = fresh_seed() if a.seed is None else a.seed
    reading = Reading(frame=a.frame, pose=a.pose, spacing=a.spacing)
    plan = runtime.plan_augment(read_curves(a.input), mode=a.mode, seed=seed, neighbours=a.neighbours, reading=reading)
    start, stop = a.offset, a.offset + a.count
    step = runtime.graphs.batch_size
    spacing = runtime.reading(reading).spacing
    with bar(a.count, "augment", enabled=shown(a.no_progress)) as progress:
        if a.output.endswith(".npy"):  # streamed chunk by chunk: any count in bounded memory
            if a.metrics:
                raise ValueError("--metrics needs a JSON output: a .npy file holds the curves alone")
            shape = (a.count, runtime.mix_length(plan.prep, a.n_points), 2)
            chunks = runtime.augment_chunks(plan, start, stop, n_points=a.n_points, spacing=spacing, chunk=step)
            write_npy_chunks(a.output, shape, counted(chunks, progress))
        else:
            parts = []  # chunk by chunk for the bar; a count of 0 still makes one (empty) chunk of the right shapes
            for i in range(start, stop, step) or [start]:
                parts.append(runtime.augment(plan, i, min(i + step, stop), n_points=a.n_points, spacing=spacing))
                progress.update(len(parts[-1].curves))
            made = Augmented(
                np.concatenate([p.curves for p in parts]),
                [f for p in parts for f in p.frames],
                None,
                sources=np.concatenate([p.sources for p in parts]),
                weights=np.concatenate([p.weights for p in parts]),
                seed=seed,
                offset=a.offset,
            )
            shape = made.curves.shape
            write_output(a.output, augment_body(made, metrics=a.metrics))
    print(f"{a.output}: {a.count} new curves of {shape[1]} points ({a.mode}s), seed {seed}", file=sys.stderr)
    return 0


def cmd_fit(a: argparse.Namespace) -> int:
    from curve_vae.files import read_curves, write_output
    from curve_vae.inference.bodies import fit_body

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
    from curve_vae.files import atomic_path, read_curves
    from curve_vae.geometry import revolve

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
        help="curves as points, as B-splines (control points, knots, params), or both; JSON only (default: points)",
    )
    add_model_options(s)
    s.set_defaults(func=cmd_sample)


def _add_augment(sub: argparse._SubParsersAction) -> None:
    s = sub.add_parser("augment", help="new curves between given curves, offline (as POST /augment)")
    s.add_argument("input", help="seed curves: .json ([curve, …] or {curves: …}), .npy (N, n, 2), or - (stdin)")
    add_generate_options(s)
    s.add_argument("--mode", choices=choices(AugmentMode), default="pair", help="sources per new curve (default: pair)")
    s.add_argument(
        "--neighbours",
        type=int,
        default=None,
        help="mix each curve only with its k nearest in latent space (default: any)",
    )
    s.add_argument("--offset", type=int, default=0, help="index of the first curve in the seeded sequence (default: 0)")
    s.add_argument(
        "--frame", choices=choices(FrameMode), default="auto", help="frame of the seed curves (default: auto)"
    )
    s.add_argument(
        "--pose",
        choices=choices(Pose),
        default="auto",
        help="how each seed curve is turned before it is encoded, as the service's `pose` (auto: the model's own "
        "reading; new curves come back in their sources' poses) (default: auto)",
    )
    add_model_options(s)
    s.set_defaults(func=cmd_augment)


def _add_fit(sub: argparse._SubParsersAction) -> None:
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
        choices=choices(FitParam),
        default="chord",
        help="parameter of each point: chord length (any curve) or uniform (the "
        "data set's sampling; recovers its B-splines exactly) (default: chord)",
    )
    s.add_argument("--n-points", type=int, default=None, help="also write each fitted spline at this many points")
    s.set_defaults(func=cmd_fit)


def _add_revolve(sub: argparse._SubParsersAction) -> None:
    s = sub.add_parser("revolve", help="surface of revolution of a profile curve, as OBJ or STL (paper Fig. 12)")
    s.add_argument("input", help="one profile curve: .json, .npy, or - (stdin)")
    s.add_argument("-o", "--output", required=True, help="mesh file (.obj or .stl)")
    s.add_argument("--format", choices=choices(MeshFormat), default="", help="default: from the file name")
    s.add_argument("--segments", type=int, default=64, help="angular resolution (default: 64)")
    s.add_argument(
        "--axis", choices=choices(Axis), default="y", help="revolve about a vertical (y) or horizontal (x) line"
    )
    s.add_argument(
        "--axis-position",
        type=float,
        default=None,
        help="where that line is (default: through the profile's nearest point)",
    )
    s.set_defaults(func=cmd_revolve)


def register(sub: argparse._SubParsersAction) -> None:
    _add_sample(sub)
    _add_augment(sub)
    _add_fit(sub)
    _add_revolve(sub)
