"""Curve files for the offline commands: JSON (as the REST API speaks it), NPY, and airfoil coordinate files (.dat)."""

from __future__ import annotations

import json
import os
import sys
import tempfile
from collections.abc import Iterable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import numpy as np


def read_curves(path: str) -> list[np.ndarray]:
    """Curves from a .npy array (n, 2) or (N, n, 2), an airfoil .dat file, CSV (x,y rows; a blank line between
    curves), or JSON: [[x, y], …], [curve, …], {"curves": […]} or {"curve": […]} (a /revolve body).

    "-" reads JSON from standard input.
    """
    if path.endswith(".npy"):
        arr = np.load(path, allow_pickle=False)
        data: Any = arr[None] if arr.ndim == 2 else arr
    elif path.endswith(".dat"):
        data = [parse_dat(Path(path).read_text(errors="replace"), path)]
    elif path.endswith(".csv"):
        data = parse_csv(Path(path).read_text(errors="replace"), path)
    else:
        text = sys.stdin.read() if path == "-" else Path(path).read_text()
        data = json.loads(text)
        if isinstance(data, dict):
            if "curves" in data:
                data = data["curves"]
            elif "curve" in data:
                data = [data["curve"]]
            else:
                raise ValueError(f"{path}: a JSON object needs a 'curves' field (or 'curve', as /revolve takes it)")
        if data and isinstance(data[0], list | tuple) and data[0] and not isinstance(data[0][0], list | tuple):
            data = [data]  # a single curve
    curves = [np.asarray(c, dtype=np.float64) for c in data]
    for i, c in enumerate(curves):
        if c.ndim != 2 or c.shape[1] != 2:
            raise ValueError(f"{path}: curve {i} must be a list of [x, y] pairs, got shape {c.shape}")
        if not np.isfinite(c).all():
            j = int(np.argwhere(~np.isfinite(c))[0][0])
            raise ValueError(f"{path}: curve {i} point {j} is not finite")
    return curves


CURVE_SUFFIXES = (".npy", ".csv", ".json", ".dat")


def read_curve_files(source: str | Path) -> list[np.ndarray]:
    """Every curve of a file, or of every .npy/.csv/.json/.dat file under a directory (sorted by path)."""
    src = Path(source)
    if src.is_dir():
        paths = sorted(p for p in src.rglob("*") if p.suffix in CURVE_SUFFIXES and p.is_file())
        if not paths:
            raise ValueError(f"{src}: no curve files ({', '.join(CURVE_SUFFIXES)}) in this directory")
    elif src.is_file():
        paths = [src]
    else:
        raise ValueError(f"{src}: no such file or directory")
    return [c for p in paths for c in read_curves(str(p))]


def parse_csv(text: str, name: str = "<csv>") -> list[np.ndarray]:
    """Curves from CSV: a row `x,y` per point (a header row is skipped); a blank line starts the next curve.
    ValueError names the file and line."""
    curves: list[list[tuple[float, float]]] = [[]]
    for number, line in enumerate(text.splitlines(), start=1):
        parts = [p.strip() for p in line.split(",")]
        if not any(parts):
            if curves[-1]:
                curves.append([])
            continue
        try:
            values = [float(p) for p in parts]
        except ValueError:
            if number == 1:
                continue  # a header such as x,y
            raise ValueError(f"{name}:{number}: expected two numbers x,y, got {line.strip()!r}") from None
        if len(values) != 2 or not np.isfinite(values).all():
            raise ValueError(f"{name}:{number}: expected two finite numbers x,y, got {line.strip()!r}")
        curves[-1].append((values[0], values[1]))
    found = [np.array(c) for c in curves if c]
    if not found:
        raise ValueError(f"{name}: no coordinates found")
    for c in found:
        if len(c) < 4:
            raise ValueError(f"{name}: a curve of {len(c)} points; a curve needs at least 4")
    return found


def parse_dat(text: str, name: str = "<dat>") -> np.ndarray:
    """One airfoil from a coordinate file (n, 2): Selig format (a title line, then x y from the trailing edge over one
    surface to the leading edge and back) or Lednicer format (a title line, a line of the two surfaces' point counts,
    then each surface from leading to trailing edge), returned in Selig order. ValueError names the file and line.
    """
    rows: list[tuple[int, float, float]] = []
    for number, line in enumerate(text.splitlines(), start=1):
        parts = line.replace(",", " ").split()
        if not parts:
            continue
        try:
            values = [float(p) for p in parts]
        except ValueError:
            if rows:
                raise ValueError(f"{name}:{number}: expected two numbers x y, got {line.strip()!r}") from None
            continue  # the title line(s)
        if len(values) != 2 or not np.isfinite(values).all():
            raise ValueError(f"{name}:{number}: expected two finite numbers x y, got {line.strip()!r}")
        rows.append((number, values[0], values[1]))
    if not rows:
        raise ValueError(f"{name}: no coordinates found")
    pts = np.array([r[1:] for r in rows])
    if pts[0].min() >= 2 and float(pts[0, 0]).is_integer() and float(pts[0, 1]).is_integer():  # Lednicer counts
        upper, lower = int(pts[0, 0]), int(pts[0, 1])
        if len(pts) - 1 != upper + lower:
            raise ValueError(f"{name}:{rows[0][0]}: counts {upper} + {lower} but {len(pts) - 1} points follow")
        up, lo = pts[1 : 1 + upper], pts[1 + upper :]
        pts = np.concatenate([up[::-1], lo[1:] if np.allclose(lo[0], up[0]) else lo])
    if len(pts) < 4:
        raise ValueError(f"{name}: {len(pts)} points; a curve needs at least 4")
    return pts


def refuse_overwrite(path: str | Path, force: bool, flag: str = "-o") -> None:
    """Stop before any work when `path` exists and the user did not pass --force: nothing of theirs is replaced."""
    if str(path) != "-" and Path(path).exists() and not force:
        raise ValueError(f"{path} exists and is left as it is: pass --force to replace it, or give another {flag}")


def write_output(path: str, payload: dict[str, Any], array_key: str | None = None) -> None:
    """JSON to `path` ("-": standard output); a .npy path gets payload[array_key] as an array."""
    if path.endswith(".npy"):
        if array_key is None:
            raise ValueError("this command writes JSON only; give a .json path")
        tmp = Path(path).with_suffix(".npy.tmp")
        with open(tmp, "wb") as f:
            np.save(f, np.asarray(payload[array_key], dtype=np.float32))
        tmp.replace(path)
        return
    text = json.dumps(payload, indent=None, separators=(",", ":")) + "\n"
    if path == "-":
        sys.stdout.write(text)
    else:
        tmp = Path(path + ".tmp")
        tmp.write_text(text)
        tmp.replace(path)


def write_npy_chunks(path: str, shape: tuple[int, ...], chunks: Iterable[np.ndarray]) -> None:
    """A float32 .npy of `shape` written chunk by chunk (memory bounded by one chunk), in place when complete."""
    from curve_vae.npy import npy_chunks

    tmp = Path(path + ".tmp")
    try:
        with open(tmp, "wb") as f:
            for block in npy_chunks(shape, chunks):
                f.write(block)
        tmp.replace(path)
    finally:
        tmp.unlink(missing_ok=True)


# ------------------------------------------------- atomic output: never a half-written file


@contextmanager
def atomic_path(path: str | Path) -> Iterator[Path]:
    """Yield a temporary path beside `path`; on success rename it over `path` (mode 0644).

    On any error the temporary file is removed and `path` keeps its previous content.
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    os.close(fd)
    try:
        yield Path(tmp)
        os.chmod(tmp, 0o644)
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def atomic_write_text(path: str | Path, text: str) -> None:
    with atomic_path(path) as tmp:
        tmp.write_text(text)
