"""`curve-vae reconstruct` and `encode`: curve files through the model, locally or, with --server, on a deployment;
the JSON the endpoints answer either way."""

from __future__ import annotations

import argparse
import sys
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

from curve_vae.commands.options import (
    add_model_options,
    add_reading_options,
    add_server_option,
    model_runtime,
    reading_fields,
    server_client,
)
from curve_vae.curvefiles.help import INPUT_HELP, OUTPUT_HELP
from curve_vae.errors import InvalidInput
from curve_vae.files import refuse_overwrite
from curve_vae.inference.choices import Output, choices
from curve_vae.inference.reading import Reading


def cmd_reconstruct(a: argparse.Namespace) -> int:
    from curve_vae.curvefiles import read_curves, write_output
    from curve_vae.inference.results import reconstruct_body

    refuse_overwrite(a.output, a.force)
    reading = reading_fields(a)
    curves = read_curves(a.input)
    if a.server:
        with server_client(a) as c:
            rec = c.reconstruct(curves, **reading, n_points=a.n_points, output=a.output_as, metrics=a.metrics)
            served: dict[str, Any] = {}
            if a.output_as != "bspline":
                served["curves"] = [np.asarray(x).tolist() for x in rec.curves]
            served["mse"] = rec.mse.tolist()
            if rec.closeness is not None:
                served["closeness"] = rec.closeness.json()
            if rec.repaired is not None:
                served["repaired"] = rec.repaired.tolist()
            if a.output_as != "points":
                served["splines"] = rec.splines
            if a.metrics:
                served["metrics"] = rec.metrics
            body: Mapping[str, Any] = served
    else:
        rec = model_runtime(a).reconstruct(curves, Reading(**reading), n_points=a.n_points)
        body = reconstruct_body(rec, metrics=a.metrics, output=a.output_as)
    if Path(a.output).suffix.lower() in DRAWINGS:  # a drawing: the inputs beside their reconstructions, as the page
        drawing, marks = with_inputs(curves, body)
        write_output(a.output, drawing, marks=marks)
    else:
        write_output(a.output, body, array_key="curves" if "curves" in body else None)
    print(f"{a.output}: {reconstruct_summary(body)}", file=sys.stderr)
    return 0


#: Outputs that are drawings (curvefiles.writing): they hold the inputs too.
DRAWINGS = (".svg", ".dxf")


def with_inputs(inputs: list[np.ndarray], body: Mapping[str, Any]) -> tuple[dict[str, Any], list[Mapping[str, Any]]]:
    """A reconstruction's answer as a drawing the page would export: each input, named A, B, … (role input), then its
    reconstruction (role reconstruction, of its input), a B-spline where the answer holds splines; and the marks."""
    from curve_vae.curvefiles.roles import curve_name

    names = [curve_name(k) for k in range(len(inputs))]
    recon = body.get("curves")
    splines = body.get("splines")
    curves = [np.asarray(c, np.float64).tolist() for c in inputs] + (list(recon) if recon is not None else [])
    drawing: dict[str, Any] = {"curves": curves}
    if splines:
        drawing["splines"] = [None] * len(inputs) + list(splines)
    marks: list[Mapping[str, Any]] = [{"role": "input", "name": n} for n in names]
    marks += [{"role": "reconstruction", "name": f"{n} reconstructed", "of": n} for n in names]
    return drawing, marks


def reconstruct_summary(body: Mapping[str, Any]) -> str:
    """One line a person reads: how close the curves came relative to their size, the worst point and where it is,
    how many were untangled, and the paper's MSE in the curves' own units."""
    mse = np.asarray(body["mse"], np.float64)
    line = f"{len(mse)} curves reconstructed"
    near = body.get("closeness") or []
    if near:
        rms = np.array([c["rms"] if c["rms"] is not None else np.inf for c in near])
        worst = np.array([c["max"] if c["max"] is not None else np.inf for c in near])
        w = int(np.argmax(worst))
        line += (
            f", RMS {100 * rms.mean():.3g}% of the diagonal (mean), worst point {100 * worst[w]:.3g}%"
            f" (curve {w}, point {near[w]['max_at']})"
        )
    repaired = int(np.sum(body.get("repaired") or []))
    if repaired:
        line += f", {repaired} untangled where they crossed themselves"
    return line + f"; MSE (paper eq. 4) mean {mse.mean():.4g}"


def cmd_encode(a: argparse.Namespace) -> int:
    from curve_vae.curvefiles import read_curves, write_output
    from curve_vae.inference.results import encode_body

    refuse_overwrite(a.output, a.force)
    if a.output != "-" and Path(a.output).suffix.lower() not in ("", ".json"):
        raise InvalidInput(f"{a.output}: encode writes latents as JSON (a .json file, or - for stdout)")
    reading = reading_fields(a)
    curves = read_curves(a.input)
    if a.server:
        with server_client(a) as c:
            enc = c.encode(curves, **reading)
            latents: dict[str, Any] = {"mean": enc.mean, "log_var": enc.log_var, "frames": enc.frames}
            if enc.closeness is not None:
                latents["closeness"] = enc.closeness.json()
            body: Mapping[str, Any] = latents
    else:
        body = encode_body(model_runtime(a).encode(curves, Reading(**reading)))
    write_output(a.output, body)
    print(f"{a.output}: {len(body['mean'])} latents of {len(body['mean'][0])} numbers", file=sys.stderr)
    return 0


def _add_reading(s: argparse.ArgumentParser, output: str) -> None:
    s.add_argument("input", help=INPUT_HELP)
    s.add_argument("-o", "--output", default="-", help=f"{output} (default: - = stdout)")
    add_reading_options(s)


def register(sub: argparse._SubParsersAction) -> None:
    s = sub.add_parser("reconstruct", help="curves through the model and back, with their error (as POST /reconstruct)")
    _add_reading(s, OUTPUT_HELP)
    s.add_argument("--n-points", type=int, default=None, help="points per returned curve (default: the input's)")
    s.add_argument(
        "--output-as",
        choices=choices(Output),
        default="points",
        help="points, B-splines or both; .svg and .dxf outputs draw the B-splines exactly (default: points)",
    )
    s.add_argument("--metrics", action="store_true", help="add smoothness, self-intersection and length per curve")
    add_model_options(s)
    add_server_option(s)
    s.set_defaults(func=cmd_reconstruct)
    s = sub.add_parser("encode", help="latent mean and log-variance of each curve (as POST /encode)")
    _add_reading(s, "JSON output file")
    add_model_options(s)
    add_server_option(s)
    s.set_defaults(func=cmd_encode)
