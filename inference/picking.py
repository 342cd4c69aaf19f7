"""Which of a curve's candidate readings the reader keeps (inference.reader): pose "learned"'s best by the reading
ranker, and, for a set that is mixed together, the one pose the whole set is read in.

    candidates (k, 161, 2) --ranker.scores--> each curve's `count` best, distinct (`ranked`) --encoded--> (the closest
        decoded kept where there are several)
"""

from __future__ import annotations

import numpy as np

from curve_vae.inference.ranker import Ranker
from curve_vae.inference.reading import Candidate

#: Candidates whose model-plane points all lie within this (plane units; the plane is 128 across) are one reading:
#: a symmetric curve reversed and mirrored end for end is itself again.
SAME_POINTS = 1e-3


def ranked(ranker: Ranker, stage: list[Candidate], models: np.ndarray, *, shared: bool, count: int) -> list[np.ndarray]:
    """Which candidates pose "learned" encodes, per curve, best first: the `count` the ranker expects closest;
    shared: in the one pose whose expected errors (each curve's least, relative to its size) sum least over the set."""
    score = ranker.scores(models)
    owner = np.array([c.curve for c in stage])
    if shared:
        pose = np.array([c.pose for c in stage])
        curves = range(int(owner.max()) + 1)
        expected = {
            int(p): sum(float(np.exp(score[(pose == p) & (owner == i)].min())) for i in curves) for p in np.unique(pose)
        }
        chosen = min(expected, key=expected.__getitem__)
        score = np.where(pose == chosen, score, np.inf)
    return [
        distinct(rows[np.argsort(score[rows], kind="stable")], models, count)
        for rows in (np.flatnonzero((owner == i) & (score < np.inf)) for i in np.unique(owner))
    ]


def distinct(ranked: np.ndarray, models: np.ndarray, count: int) -> np.ndarray:
    """The first `count` of `ranked` (candidate rows, best first) whose model-plane points differ from those kept."""
    kept = [int(ranked[0])]
    for k in ranked[1:]:
        if len(kept) == count:
            break
        if all(np.abs(models[k] - models[j]).max() > SAME_POINTS for j in kept):
            kept.append(int(k))
    return np.array(kept)


def in_shared_pose(inputs: list[np.ndarray], stage: list[Candidate], err: np.ndarray) -> np.ndarray:
    """The candidates' errors with every pose but the set's best made infinite: the best pose is the one whose
    closest candidate per curve (a mean squared distance, so that long curves do not outweigh short ones) sums least
    over the set; each curve then keeps its closest candidate in that pose (its spacing)."""
    owner = np.array([c.curve for c in stage])
    pose = np.array([c.pose for c in stage])
    per_point = err / np.array([len(inputs[o]) for o in owner])
    totals = {}
    for p in np.unique(pose):
        totals[int(p)] = float(sum(per_point[(pose == p) & (owner == i)].min() for i in range(len(inputs))))
    chosen = min(totals, key=totals.__getitem__)
    return np.where(pose == chosen, err, np.inf)
