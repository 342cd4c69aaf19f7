"""How close each way of reading brings users' curves back, and what it costs: the readings' frontier of
docs/RESULTS.md "Readings", its table and its plot, from one run.

Two groups of sets, seeded:
- users' curves: 40 paper test curves as drawn; 40 resampled by arc length to 50 and 40 to 161 points, turned,
  mirrored and reversed at random; 40 turned and reversed as drawn; 10 analytic shapes, moved; 40 real UIUC
  airfoils (none of them labelled for the ranker);
- the family suite (training/suite.py): `--count` curves of each family, trained and held out.

Each cell: mean relative RMSE (% of the bounding-box diagonal, at the curve's own points). Cost: milliseconds of
one core a curve (one onnxruntime thread, encoding cache off), the users' sets read a set a request ("in a set") and
the paper's curves as drawn one request each ("alone"). Crossing: answers that cross themselves where their input
does not, after untangling, over every set. The readings: service 0.26.0's default (the ranker's two candidates, the
closer kept, the ends as decoded; 0.26.0 read the second only where the first came back farther than 0.05%); the
ranker's two, the ends kept; the ranker's first alone; the canonical pose at the natural spacing; one encoding
(canonical, as given); each with 0–3 looks again (inference.looking); the search; refine 2.

    .venv/bin/python scripts/reading_table.py [--count 100] [--json out.json] [--plot out.png] [--morphs 40]

`--readings`: some rows only (their names as printed). `--morphs N`: also the morph suite (training/morphs.py: N
pairs of paper curves drawn in one pose, swept in 7 steps) for the default: how far in-betweens turn and drift.
"""

from __future__ import annotations

import argparse
import json
import os
import time
from dataclasses import dataclass

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")  # one core, as the service's inference threads run

import numpy as np  # noqa: E402

from curve_vae.geometry.frame import resample  # noqa: E402
from curve_vae.geometry.validity import new_crossings  # noqa: E402
from curve_vae.inference.reading import Reading  # noqa: E402
from curve_vae.inference.runtime import CurveRuntime  # noqa: E402
from curve_vae.training.suite import (  # noqa: E402
    AIRFOIL_WHEEL,
    paper_test_split,
    random_moves,
    relative_rmse,
    suite_sets,
)


@dataclass(frozen=True)
class Row:
    """One reading of the table: its request fields and how many of the ranker's candidates it reads."""

    name: str
    fields: dict
    ranked_reads: int = 1
    base: str = ""  # the reading it adds looks to (the plot joins them)
    keep_ends: bool = True  # False: the ends as decoded (service 0.26.0's answers)

    @property
    def reading(self) -> Reading:
        return Reading(**self.fields)


def _with_looks(name: str, fields: dict, ranked_reads: int = 1, looks: tuple[int, ...] = (0, 1, 2, 3)) -> list[Row]:
    return [
        Row(f"{name}, {k} look{'s' if k != 1 else ''}", {**fields, "looks": k}, ranked_reads, base=name) for k in looks
    ]


ROWS: list[Row] = [
    Row("0.26.0's default", {"looks": 0}, ranked_reads=2, keep_ends=False),
    *_with_looks("the ranker's two", {}, ranked_reads=2),
    *_with_looks("the ranker's first", {}),
    *_with_looks("canonical, natural", {"pose": "canonical", "spacing": "natural"}),
    *_with_looks("canonical, as given", {"pose": "canonical", "spacing": "parameter"}),
    Row("the search", {"pose": "search", "spacing": "search", "looks": 0}),
    Row("the ranker's first, 1 look, refine 2", {"refine": 2}),
]
#: The row today's answers are compared with (service 0.26.0's default), and the default chosen by this table.
BEFORE = "0.26.0's default"
DEFAULT = "the ranker's first, 1 look"


def analytic() -> list[np.ndarray]:
    """Ten analytic shapes at 120 points even in their own parameter."""
    t = np.linspace(0, 1, 120)
    a, h = 2 * np.pi * t, np.pi * t
    return [
        np.c_[np.cos(1.5 * h), np.sin(1.5 * h)],  # three quarters of a circle
        np.c_[2 * np.cos(a), np.sin(a)],  # an ellipse
        np.c_[4 * t, np.sin(3 * np.pi * t)],  # a sine wave
        np.c_[(0.3 + t) * np.cos(3 * h), (0.3 + t) * np.sin(3 * h)],  # a spiral
        np.c_[2 * t - 1, (2 * t - 1) ** 2],  # a parabola
        np.c_[np.sign(np.cos(a)) * np.abs(np.cos(a)) ** 0.5, np.sign(np.sin(a)) * np.abs(np.sin(a)) ** 0.5],
        np.c_[np.sin(2 * h), np.sin(3 * h)],  # a Lissajous figure
        np.c_[(1 - np.cos(a)) * np.cos(a), (1 - np.cos(a)) * np.sin(a)],  # a cardioid
        np.c_[3 * t, np.tanh(6 * (t - 0.5))],  # a step
        np.c_[np.cos(h), np.sin(h)],  # a half circle
    ]


def table_sets() -> dict[str, list[np.ndarray]]:
    """The users' sets (the module docstring)."""
    from curve_vae.training.airfoils import load_airfoils

    rng = np.random.default_rng(11)
    paper = [np.asarray(c, np.float64) for c in paper_test_split()[:80]]
    sets = {
        "paper, as drawn": paper[:40],
        "arc length, 50 pts": random_moves([resample(c, 50) for c in paper[40:80]], rng),
        "arc length, 161 pts": random_moves([resample(c, 161) for c in paper[:40]], rng),
        "moved": random_moves(paper[40:80], rng),
        "analytic shapes": random_moves(analytic(), rng),
    }
    if AIRFOIL_WHEEL.exists():
        sets["UIUC airfoils"] = load_airfoils(AIRFOIL_WHEEL, 40, seed=5)
    return sets


def measure(rt: CurveRuntime, row: Row, groups: dict[str, dict[str, list[np.ndarray]]]) -> dict:
    """One row: each set's mean error (%), the crossings after untangling, and the cost a curve."""
    rt.reader.ranked_reads, rt.reader.keep_ends = row.ranked_reads, row.keep_ends
    out: dict = {"fields": row.fields, "ranked_reads": row.ranked_reads, "keep_ends": row.keep_ends, "crossing": 0}
    for group, sets in groups.items():
        errors, spent, count = {}, 0.0, 0
        for name, curves in sets.items():
            t0 = time.perf_counter()
            got = rt.reconstruct(curves, row.reading).curves
            spent += time.perf_counter() - t0
            count += len(curves)
            errors[name] = float(100 * relative_rmse(curves, got).mean())
            out["crossing"] += int(new_crossings(curves, got).sum())
        out[group] = errors
        out[f"ms_{group}"] = 1000 * spent / count
    alone = groups["users"]["paper, as drawn"]
    t0 = time.perf_counter()
    for c in alone:
        rt.reconstruct([c], row.reading)
    out["ms_alone"] = 1000 * (time.perf_counter() - t0) / len(alone)
    rt.reader.ranked_reads, rt.reader.keep_ends = 1, True
    return out


def geomean(values: dict[str, float]) -> float:
    return float(np.exp(np.mean(np.log(list(values.values())))))


def verdict(table: dict[str, dict]) -> dict[str, dict[str, float]]:
    """Each row against BEFORE: the least and the most its error is closer by over the users' sets and over the family
    suite, and its cost a curve in a set over BEFORE's."""
    before = table[BEFORE]
    out = {}
    for name, row in table.items():
        ratios = {g: [before[g][s] / row[g][s] for s in row[g]] for g in ("users", "suite")}
        out[name] = {
            "users_closer_min": min(ratios["users"]),
            "users_closer_max": max(ratios["users"]),
            "suite_closer_min": min(ratios["suite"]),
            "suite_closer_max": max(ratios["suite"]),
            "cost": row["ms_users"] / before["ms_users"],
        }
    return out


def plot(table: dict[str, dict], path: str) -> None:
    """Error (the sets' geometric mean) against cost a curve, a panel a group; a line joins a reading's looks."""
    import matplotlib
    import matplotlib.ticker

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(12, 5.6), sharex=True)
    bases: dict[str, list[str]] = {}
    for row in ROWS:
        if row.name in table:
            bases.setdefault(row.base or row.name, []).append(row.name)
    for ax, group, title in zip(axes, ("users", "suite"), ("users' curves (6 sets)", "the family suite")):
        for i, (base, names) in enumerate(bases.items()):
            x = [table[n]["ms_users"] for n in names]
            y = [geomean(table[n][group]) for n in names]
            ax.plot(x, y, "o-" if len(names) > 1 else "s", color=f"C{i}", label=base)
            if len(names) > 1:
                for k, (xi, yi) in enumerate(zip(x, y)):
                    ax.annotate(str(k), (xi, yi), textcoords="offset points", xytext=(4, 4), fontsize=8)
        for name, marker, label in ((BEFORE, "x", "0.26.0's default"), (DEFAULT, "*", "the default")):
            if name in table:
                ax.plot(table[name]["ms_users"], geomean(table[name][group]), marker, color="k", ms=14, mfc="none",
                        label=label)  # fmt: skip
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.xaxis.set_major_formatter(matplotlib.ticker.FuncFormatter(lambda v, _: f"{v:g}"))
        ax.yaxis.set_major_formatter(matplotlib.ticker.FuncFormatter(lambda v, _: f"{v:g}"))
        ax.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
        ax.yaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
        ax.set_xticks([3, 5, 7, 10, 15, 20, 30, 40])
        ax.set_yticks([0.03, 0.04, 0.05, 0.07, 0.1, 0.15, 0.2])
        ax.set_xlabel("ms of one core a curve, read in a set (log)")
        ax.set_ylabel("error, % of the diagonal (geometric mean of the sets, log)")
        ax.set_title(title)
        ax.grid(True, which="both", alpha=0.3)
    handles, labels = axes[0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="lower center", ncol=4, fontsize=9)
    fig.suptitle("Readings: closeness against cost (numbers: looks again)")
    fig.tight_layout(rect=(0, 0.12, 1, 1))
    fig.savefig(path, dpi=110)


def markdown(table: dict[str, dict], verdicts: dict[str, dict]) -> str:
    users = list(next(iter(table.values()))["users"])
    head = (
        "| reading | "
        + " | ".join(users)
        + " | suite (mean) | ms a curve in a set / alone | closer (users, suite) | crossing |"
    )
    lines = [head, "|" + "---|" * (len(users) + 6)]
    for name, r in table.items():
        v = verdicts[name]
        mark = f"**{name}**" if name == DEFAULT else name
        cells = " | ".join(f"{r['users'][s]:.3f}%" for s in users)
        lines.append(
            f"| {mark} | {cells} | {np.mean(list(r['suite'].values())):.3f}% | {r['ms_users']:.1f} / "
            f"{r['ms_alone']:.1f} | {v['users_closer_min']:.2f}–{v['users_closer_max']:.2f}×, "
            f"{v['suite_closer_min']:.2f}–{v['suite_closer_max']:.2f}× | {r['crossing']} |"
        )
    return "\n".join(lines)


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--model-dir", default="models")
    p.add_argument("--count", type=int, default=100, help="curves a set of the family suite (default 100)")
    p.add_argument("--json", default="", help="also write the table here")
    p.add_argument("--plot", default="", help="also draw the frontier here (PNG)")
    p.add_argument("--readings", nargs="*", default=[r.name for r in ROWS], help="rows (default: all)")
    p.add_argument("--morphs", type=int, default=0, help="pairs of the morph suite for the default (default: none)")
    p.add_argument("--replot", default="", help="draw --plot from a table written with --json, measuring nothing")
    a = p.parse_args()
    if a.replot:
        plot(json.loads(open(a.replot).read())["readings"], a.plot)
        return
    rt = CurveRuntime.load(a.model_dir, intra_op_threads=1, cache_bytes=0)
    suite = {name: curves for name, (_, curves) in suite_sets(paper_test_split(), a.count).items()}
    groups = {"users": table_sets(), "suite": suite}
    table = {}
    for row in ROWS:
        if row.name not in a.readings:
            continue
        table[row.name] = r = measure(rt, row, groups)
        cells = "".join(f"{v:9.3f}%" for v in r["users"].values())
        print(
            f"{row.name:40s}{cells}  suite {np.mean(list(r['suite'].values())):.3f}%  {r['ms_users']:6.1f} / "
            f"{r['ms_alone']:5.1f} ms  crossing {r['crossing']}",
            flush=True,
        )
    out: dict = {"readings": table}
    if BEFORE in table:
        out["verdicts"] = verdicts = verdict(table)
        print(markdown(table, verdicts))
    if a.morphs:
        from curve_vae.training.morphs import format_morphs, morph_pairs, run_morphs

        rows, pairs = {r.name: r for r in ROWS}, morph_pairs(paper_test_split(), a.morphs)
        out["morphs"] = {}
        for name in (BEFORE, DEFAULT):
            rt.reader.ranked_reads, rt.reader.keep_ends = rows[name].ranked_reads, rows[name].keep_ends
            out["morphs"] |= run_morphs(rt, pairs, readings={name: rows[name].reading})
        rt.reader.ranked_reads, rt.reader.keep_ends = 1, True
        print(format_morphs(out["morphs"]))
    if a.json:
        with open(a.json, "w") as fh:
            json.dump(out, fh, indent=2)
    if a.plot and BEFORE in table:
        plot(table, a.plot)


if __name__ == "__main__":
    main()
