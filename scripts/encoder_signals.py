"""Can the encoder alone tell which of the ranker's two candidates a curve reads closer, so that only one is decoded?
Per set, every curve's first- and second-ranked candidates are both encoded and decoded (pose "learned"), and each
rule that picks one of the two is paired against the better of them: the ranker's first always; the one whose
latent has the smaller log-variance sum, the smaller squared mean (nearer the prior's centre), the smaller variance
sum. A rule near 1.00 would save a decoder pass; the shipped reading decodes both (scripts/close_enough.py).

    .venv/bin/python scripts/encoder_signals.py --count 100
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

from curve_vae.inference import reader
from curve_vae.inference.cpus import limit_blas_threads
from curve_vae.inference.runtime import CurveRuntime

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "scripts"))
from paired_readings import curve_sets  # noqa: E402

RULES = {  # column -> which of (first, second) a rule reads, from the two encodings' (log_var, mean)
    "log-variance": lambda lv, mu: lv.sum(axis=1),
    "squared mean": lambda lv, mu: np.square(mu).sum(axis=1),
    "variance": lambda lv, mu: np.exp(lv).sum(axis=1),
}


def both_read(record: list[tuple]) -> object:
    """Reader._first_then_second reading both candidates of every curve, recording their errors and encodings."""

    def read(self, inputs, index, stage, models, fractions, ranked):  # type: ignore[no-untyped-def]
        picks = [[int(r[0]) for r in ranked], [int(r[min(1, len(r) - 1)]) for r in ranked]]
        out = []
        for pick in picks:
            rows = self._encoded([stage[k] for k in pick], models[pick], [fractions[k] for k in pick], index)
            out.append(self._decoded(inputs, rows))
        (r1, e1), (r2, e2) = out
        for a, b, x, y in zip(r1, r2, e1, e2):
            record.append((x, y, a.log_var, b.log_var, a.mean, b.mean))
        return [a if x <= y else b for a, b, x, y in zip(r1, r2, e1, e2)]

    return read


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--count", type=int, default=100, help="curves per set (default: 100)")
    a = p.parse_args()
    limit_blas_threads(1)
    record: list[tuple] = []
    reader.Reader._first_then_second = both_read(record)  # type: ignore[method-assign]
    rt = CurveRuntime.load(ROOT / "models", providers="cpu", intra_op_threads=1, cache_bytes=0)
    print("| set | second closer | first always | " + " | ".join(RULES) + " |")
    print("|---|---|---|" + "---|" * len(RULES))
    for name, curves in curve_sets(a.count).items():
        record.clear()
        rt.reconstruct(curves)
        e = np.sqrt(np.array([r[:2] for r in record]))  # (k, 2) RMS-like: the squared distances' roots
        best = e.min(axis=1).mean()
        cells = [f"{np.mean(e[:, 1] < e[:, 0]):.0%}", f"{e[:, 0].mean() / best:.3f}"]
        for rule in RULES.values():
            s = [rule(np.stack([r[2 + k] for r in record]), np.stack([r[4 + k] for r in record])) for k in (0, 1)]
            cells.append(f"{np.where(s[1] < s[0], e[:, 1], e[:, 0]).mean() / best:.3f}")
        print(f"| {name} | " + " | ".join(cells) + " |", flush=True)


if __name__ == "__main__":
    main()
