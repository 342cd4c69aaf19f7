"""`curve-vae fit` and `revolve`: geometry tools that need no model, locally or, with --server, on a deployment (the
same output)."""

from __future__ import annotations

import argparse
import sys

from curve_vae.commands.options import add_server_option, server_client
from curve_vae.curvefiles.help import INPUT_HELP, OUTPUT_HELP
from curve_vae.errors import InvalidInput
from curve_vae.files import refuse_overwrite
from curve_vae.inference.choices import Axis, FitParam, MeshFormat, choices


def cmd_fit(a: argparse.Namespace) -> int:
    from curve_vae.curvefiles import read_curves, write_output
    from curve_vae.inference.results import fit_body

    refuse_overwrite(a.output, a.force)
    curves = read_curves(a.input)
    if a.server:
        with server_client(a) as c:
            body = c.fit(curves, n_ctrl=a.n_ctrl, tolerance=a.tolerance, param=a.param, n_points=a.n_points).json()
    else:
        body = fit_body(curves, a.n_ctrl, param=a.param, n_points=a.n_points, tolerance=a.tolerance)
    write_output(a.output, body)
    for i, f in enumerate(body["fits"]):
        print(
            f"curve {i}: {f['n_ctrl']} control points, rms error {f['rms_error']:.4g}, max {f['max_error']:.4g}",
            file=sys.stderr,
        )
    return 0


def cmd_revolve(a: argparse.Namespace) -> int:
    from curve_vae.curvefiles import read_curves
    from curve_vae.files import atomic_path
    from curve_vae.geometry import revolve
    from curve_vae.inference.results import mesh_file

    refuse_overwrite(a.output, a.force)
    curves = read_curves(a.input)
    if len(curves) != 1:
        raise InvalidInput(f"{a.input}: revolve takes one profile curve, got {len(curves)}")
    fmt = a.format or ("stl" if a.output.endswith(".stl") else "obj")
    if a.server:
        with server_client(a) as c:
            data = c.revolve(
                curves[0], segments=a.segments, axis=a.axis, axis_position=a.axis_position, format=fmt
            ).data
        what = f"{len(data)} bytes from {a.server}"
    else:
        mesh = revolve(curves[0], segments=a.segments, axis=a.axis, axis_position=a.axis_position)
        data = mesh_file(mesh, points=len(curves[0]), segments=a.segments, axis=a.axis, fmt=fmt)
        what = f"{len(mesh.vertices)} vertices, {len(mesh.faces)} triangles"
    with atomic_path(a.output) as tmp:
        tmp.write_bytes(data)
    print(f"{a.output}: {what} ({fmt})", file=sys.stderr)
    return 0


def _add_fit(sub: argparse._SubParsersAction) -> None:
    s = sub.add_parser("fit", help="least-squares cubic B-spline of each curve (no model needed)")
    s.add_argument("input", help=INPUT_HELP)
    s.add_argument("-o", "--output", default="-", help=f"{OUTPUT_HELP}; .svg and .dxf draw the fits (default: -)")
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
    add_server_option(s)
    s.set_defaults(func=cmd_fit)


def _add_revolve(sub: argparse._SubParsersAction) -> None:
    s = sub.add_parser("revolve", help="surface of revolution of a profile curve, as OBJ or STL (paper Fig. 12)")
    s.add_argument("input", help=f"one profile curve; {INPUT_HELP}")
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
    add_server_option(s)
    s.set_defaults(func=cmd_revolve)


def register(sub: argparse._SubParsersAction) -> None:
    _add_fit(sub)
    _add_revolve(sub)
