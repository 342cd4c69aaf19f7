"""Curve files in and out, one reader and one writer for every command: JSON, CSV/TSV, NPY/NPZ, airfoil .dat, SVG
and DXF in; JSON, CSV, NPY, SVG and DXF out (`writing.py`). A file with no curve in it is a CurveFileError naming it
(and the line, where there is one); what a reader skips it says in a CurveFileWarning."""

from __future__ import annotations

import sys
import zipfile
from pathlib import Path

import numpy as np

from curve_vae.curvefiles.bezier import bezier_points, spline_beziers
from curve_vae.curvefiles.common import CurveFileError, CurveFileWarning, as_curves, warn
from curve_vae.curvefiles.dat import parse_dat
from curve_vae.curvefiles.help import CURVE_SUFFIXES, INPUT_HELP, OUTPUT_HELP, OUTPUT_SUFFIXES
from curve_vae.curvefiles.text import parse_csv, parse_json
from curve_vae.curvefiles.writing import write_output

__all__ = [
    "CURVE_SUFFIXES",
    "INPUT_HELP",
    "OUTPUT_HELP",
    "OUTPUT_SUFFIXES",
    "CurveFileError",
    "CurveFileWarning",
    "bezier_points",
    "parse_csv",
    "parse_dat",
    "parse_json",
    "read_curve_files",
    "read_curves",
    "spline_beziers",
    "write_output",
]


def _arrays(path: Path, name: str) -> list[np.ndarray]:
    """An .npy array (n, 2) or (N, n, 2); of an .npz, its `curves` or else every array of that shape, by name."""
    try:
        loaded = np.load(path, allow_pickle=False)
    except (OSError, ValueError, EOFError, zipfile.BadZipFile) as e:  # a .npy that starts like a zip is opened as one
        raise CurveFileError(f"{name}: not a numpy file ({e})") from None
    if isinstance(loaded, np.ndarray):
        arrays = [("", loaded)]
    else:
        with loaded:
            keys = ["curves"] if "curves" in loaded.files else sorted(loaded.files)
            arrays = [(k, loaded[k]) for k in keys]
    out: list[np.ndarray] = []
    for key, a in arrays:
        if a.ndim in (2, 3) and a.shape[-1] == 2 and a.dtype.kind in "fiu":
            out += list(a[None] if a.ndim == 2 else a)
        elif not key:
            raise CurveFileError(f"{name}: an array of shape {a.shape}; curves are (n, 2) or (N, n, 2)")
    if not out:
        raise CurveFileError(f"{name}: no array of shape (n, 2) or (N, n, 2) in it")
    return out


def read_curves(path: str | Path) -> list[np.ndarray]:
    """Every curve of one file, by its extension (.txt as an airfoil's .dat; anything else is read as JSON); "-" reads
    JSON from stdin."""
    name = str(path)
    if name == "-":
        return parse_json(sys.stdin.read(), "<stdin>")
    p = Path(path)
    if p.is_dir():
        raise CurveFileError(f"{name}: a folder; this command reads one curve file (give a file, or - for stdin)")
    if not p.is_file():
        raise CurveFileError(f"{name}: no such file")
    suffix = p.suffix.lower()
    if suffix in (".npy", ".npz"):
        return as_curves(_arrays(p, name), name)
    if suffix == ".svg":
        from curve_vae.curvefiles.svg import read_svg

        return read_svg(p, name)
    if suffix == ".dxf":
        from curve_vae.curvefiles.dxf import read_dxf

        return read_dxf(p, name)
    text = p.read_text(errors="replace")
    if suffix in (".dat", ".txt"):  # airfoil coordinates come as either
        return [parse_dat(text, name)]
    if suffix in (".csv", ".tsv"):
        return parse_csv(text, name)
    return parse_json(text, name)


def read_curve_files(source: str | Path) -> list[np.ndarray]:
    """Every curve of a file, or of every curve file under a directory (sorted by path; hidden ones aside). A file of
    another kind in the directory is named in a warning; a curve file that cannot be read stops it, naming the file."""
    src = Path(source)
    if src.is_dir():
        files = sorted(  # hidden files and folders (.git, .ipynb_checkpoints) are not the user's curves
            p for p in src.rglob("*") if p.is_file() and not any(q.startswith(".") for q in p.relative_to(src).parts)
        )
        paths = [p for p in files if p.suffix.lower() in CURVE_SUFFIXES]
        others = [p.relative_to(src).as_posix() for p in files if p.suffix.lower() not in CURVE_SUFFIXES]
        if others:
            warn(f"{src}: {len(others)} file(s) not of a curve kind skipped: {', '.join(others[:5])}")
        if not paths:
            raise CurveFileError(f"{src}: no curve files ({', '.join(CURVE_SUFFIXES)}) in this directory")
    elif src.is_file():
        paths = [src]
    else:
        raise CurveFileError(f"{src}: no such file or directory")
    return [c for p in paths for c in read_curves(p)]
