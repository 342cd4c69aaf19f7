"""Rankers' held-out picks by the seed their labels were drawn with: how close each ranker's first pick and the better
of its first two come to the best candidate, on the curves `curve-vae ranker train` holds out (every VAL_EVERY-th in
the label files' order), seed by seed (docs/TRAINING.md: seeds 1 and 2 the training families, 3 closed outlines).

    .venv/bin/python scripts/ranker_heldout.py runs/ranker/ranker-best.pt OTHER.pt [--labels data/ranker]
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np
import torch

from curve_vae.training.ranker import VAL_EVERY, Labels, RankerNet, _scores, pick_ratios


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("checkpoints", nargs="+", help="ranker checkpoints (RUN_DIR/ranker-best.pt)")
    p.add_argument("--labels", default="data/ranker", help="the label chunks (default: data/ranker)")
    a = p.parse_args()
    files = sorted(Path(a.labels).glob("labels-*.npz"))
    data = Labels(files)
    seed = []
    for f in files:  # each curve's seed, in the order Labels reads them
        with np.load(f) as d:
            seed += [int(d["seed"])] * len(np.unique(d["curve"]))
    seeds, held = np.array(seed), np.arange(len(data)) % VAL_EVERY == 0
    print("| checkpoint | label seed | held-out curves | first pick ÷ best | better of two ÷ best |")
    print("|---|---|---|---|---|")
    for ck in a.checkpoints:
        net = RankerNet()
        net.load_state_dict(torch.load(ck, map_location="cpu", weights_only=False)["model"])
        net.eval()
        for s in np.unique(seeds):
            m = held & (seeds == s)
            r = pick_ratios(_scores(net, data.x[m]), data.y[m], data.mask[m])
            print(f"| {ck} | {s} | {int(m.sum())} | {r['first']:.3f}× | {r['best_of_2']:.3f}× |", flush=True)


if __name__ == "__main__":
    main()
