"""`curve-vae` command line: train, export and serve the model; reconstruct, encode, sample, augment, fit and revolve
curves; fit priors to your own.

Commands: dataset, train, average, ranker, spacer, export, evaluate, triton, warm-up, reconstruct, encode, sample,
augment, fit, revolve, prior, evaluate-prior, serve.

The commands live in `curve_vae/commands/`, one module per group; this module assembles the parser.
Each subcommand imports what it needs when it runs, so `curve-vae serve` and the offline
commands (sample, augment, fit, revolve) work in the base install (no torch).
"""

from __future__ import annotations

import argparse
import sys
import warnings
from typing import TextIO

from curve_vae import __version__
from curve_vae.commands import curves, data, design, generate, model, priors, ranker, spacer, train
from curve_vae.errors import CurveVaeError


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="curve-vae",
        description=" ".join(__doc__.split("\n\n")[0].split()),
        formatter_class=argparse.ArgumentDefaultsHelpFormatter,
    )
    p.add_argument("--version", action="version", version=f"curve-vae {__version__}")
    sub = p.add_subparsers(dest="command", required=True, metavar="COMMAND")
    for group in (data, train, ranker, spacer, model, curves, generate, design, priors):
        group.register(sub)

    s = sub.add_parser("serve", help="run the REST service on a model directory")
    try:
        from curve_vae.service.server import configure_parser, run
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
        ("reconstruct", "the output file"),
        ("encode", "the output file"),
        ("prior", "the prior's file"),
        ("evaluate-prior", "the --out report and the --figure"),
    ]:
        sub.choices[name].add_argument("--force", action="store_true", help=f"replace {what} if it exists")
    return p


def _show_file_warnings(command: str) -> None:
    """What a curve file's reader skipped, as one line the user reads (not Python's warning with its source line)."""
    from curve_vae.curvefiles.common import CurveFileWarning

    shown = warnings.showwarning

    def show(
        message: Warning | str,
        category: type[Warning],
        filename: str,
        lineno: int,
        file: TextIO | None = None,
        line: str | None = None,
    ) -> None:
        if issubclass(category, CurveFileWarning):
            print(f"curve-vae {command}: warning: {message}", file=sys.stderr)
        else:
            shown(message, category, filename, lineno, file, line)

    warnings.simplefilter("always", CurveFileWarning)
    warnings.showwarning = show


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    with warnings.catch_warnings():
        _show_file_warnings(args.command)
        try:
            return int(args.func(args) or 0)
        except (CurveVaeError, OSError) as e:  # what curve-vae raises on purpose, and files it cannot open or write:
            print(f"curve-vae {args.command}: error: {e}", file=sys.stderr)  # anything else is a bug: its traceback
            return 2


if __name__ == "__main__":
    sys.exit(main())
