"""The README's pair swept with each curve read alone (service 0.13.0's /interpolate) and read as one set (now): the
figure docs/RESULTS.md shows, docs/figures/readme_pair_sweep.png.

    .venv/bin/python scripts/morph_figure.py docs/figures/readme_pair_sweep.png

Both sweeps come from the shipped model through the runtime: "alone" reads each curve in its own pose (its own
rotation, mirror image and point order) and blends the frames; "as a set" is `CurveRuntime.interpolate`.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from curve_vae.files import atomic_path  # noqa: E402
from curve_vae.geometry.morph import chord_directions, end_drift, turn_excess  # noqa: E402
from curve_vae.inference.runtime import CurveRuntime  # noqa: E402

PAIR = [
    np.array([[0, 0], [1, 2], [2.5, 3.2], [4, 3.5], [5.5, 3], [7, 1.5], [8, 0]], float),
    np.array([[0, 0], [1.5, 0.5], [3, 2], [4, 4], [5, 6.5], [6.5, 8], [8, 8.5]], float),
]


def sweeps(rt: CurveRuntime, steps: int = 5) -> dict[str, np.ndarray]:
    weights = np.array([[1 - t, t] for t in np.linspace(0, 1, steps)])
    alone = rt.mix(rt.prepare(PAIR, decoded=False), weights)  # each curve in its own pose, as 0.13.0 read them
    return {"each curve read alone (0.13.0)": np.stack(alone.curves), "read as a set": np.stack(rt.interpolate(
        PAIR, weights).curves)}  # fmt: skip


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("out", help="the figure (.png)")
    p.add_argument("--model-dir", default=str(Path(__file__).resolve().parents[1] / "models"))
    a = p.parse_args()
    rt = CurveRuntime.load(a.model_dir, cache_bytes=0)
    made = sweeps(rt)
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.6))
    colours = plt.cm.viridis(np.linspace(0, 0.9, 5))
    for ax, (title, sweep) in zip(axes, made.items()):
        for c in PAIR:
            ax.plot(*c.T, color="0.75", lw=5, zorder=0)
        for k, (c, col) in enumerate(zip(sweep, colours)):
            ax.plot(*c.T, color=col, lw=1.8, label=f"w = {k / (len(sweep) - 1):.2f}")
            ax.plot(*c[0], "o", color=col, ms=4)
        chords = ", ".join(f"{d:.0f}°" for d in np.degrees(chord_directions(sweep)))
        ax.set_title(
            f"{title}\nchords {chords}; turn excess {turn_excess(sweep):.0f}°, end drift {end_drift(sweep):.2f}",
            fontsize=9,
        )
        ax.set_aspect("equal")
        ax.grid(alpha=0.3)
    axes[0].legend(fontsize=8, loc="upper left")
    fig.suptitle("/interpolate between the README's pair (grey), 5 steps: dots mark each curve's first point")
    fig.tight_layout()
    with atomic_path(a.out) as tmp:
        fig.savefig(tmp, dpi=110, format="png")
    print(f"{a.out}: " + "; ".join(f"{k}: {np.degrees(chord_directions(v)).round(0)}" for k, v in made.items()))


if __name__ == "__main__":
    main()
