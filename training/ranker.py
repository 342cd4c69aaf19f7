"""The reading ranker: a small network that tells, from a candidate reading's model-plane points alone, how close the
frozen model will bring it back, so that the runtime encodes only the two best of the search's candidates.

    curve --the search's candidates (6 poses × as given / natural)--> (k, 161, 2) --ranker--> predicted log error
        --the two lowest--> encoder, decoder --the closer kept--> the reading

Trained on labels.npz chunks (training/ranker_labels.py): each candidate's relative RMSE through the frozen model.
The loss ranks within each curve: the predicted log errors, centred per curve, regress the measured ones, and a
softmax over each curve's candidates learns which one is closest (learned canonicalisation against a frozen model,
as equiadapt trains its canonicalisers with a prior on the labels).

Training is time-budgeted and resumable (`ranker-last.pt`, written atomically each epoch); `export_ranker` writes
the net as ranker.onnx beside the model's graphs, which inference.ranker runs in onnxruntime (the service has no
torch).
"""

from __future__ import annotations

import json
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import torch
from torch import nn

from curve_vae.inference.ranker import RANKER_KIND, ranker_inputs
from curve_vae.training.checkpoint import atomic_save
from curve_vae.training.parts import read_weights, write_part

#: Channels of the three strided convolutions (kernel 5, stride 2) and the hidden layer of the head.
CHANNELS = (32, 64, 96)
HIDDEN = 96
#: Temperature of the softmax over a curve's candidates (on natural-log errors: 0.1 tells 10% apart).
TEMPERATURE = 0.1
#: Weight of that softmax's cross-entropy beside the regression of the centred log errors.
CHOICE_WEIGHT = 0.3
#: Every VAL_EVERY-th labelled curve is held out of training: the picks are measured on them each epoch.
VAL_EVERY = 10


class RankerNet(nn.Module):
    """(B, 4, n) ranker inputs -> (B,) predicted natural log of the relative RMSE."""

    def __init__(self) -> None:
        super().__init__()
        layers: list[nn.Module] = []
        width = 4
        for c in CHANNELS:
            layers += [nn.Conv1d(width, c, 5, stride=2, padding=2), nn.ReLU()]
            width = c
        self.convs = nn.Sequential(*layers)
        self.head = nn.Sequential(nn.Linear(2 * width, HIDDEN), nn.ReLU(), nn.Linear(HIDDEN, 1))

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        h = self.convs(x)
        return self.head(torch.cat([h.mean(-1), h.amax(-1)], dim=1))[:, 0]

    @classmethod
    def from_weights(cls, weights: dict[str, np.ndarray]) -> RankerNet:
        """The net of a ranker.npz's weights (conv0…2_w/_b, dense0…1_w/_b: the numpy form models before 0.14.0
        shipped), so that an old model's ranker converts to ONNX without its checkpoint."""
        net = cls()
        layers = [m for m in net.convs if isinstance(m, nn.Conv1d)] + [m for m in net.head if isinstance(m, nn.Linear)]
        names = [f"conv{i}" for i in range(len(CHANNELS))] + ["dense0", "dense1"]
        state = {}
        for name, m in zip(names, layers):
            key = next(k for k, v in net.named_modules() if v is m)
            state[f"{key}.weight"] = torch.from_numpy(weights[f"{name}_w"])
            state[f"{key}.bias"] = torch.from_numpy(weights[f"{name}_b"])
        net.load_state_dict(state)
        return net


# ----------------------------------------------------------------------------------------------- the labels


class Labels:
    """Every labelled curve's candidates, padded to the most any curve has: inputs (C, K, 4, n), log errors (C, K)
    and which are real (C, K)."""

    def __init__(self, files: list[Path]) -> None:
        xs, ys = [], []
        for f in files:
            with np.load(f) as d:
                pts, owner, err = d["points"], d["curve"], d["error"]
            inputs = ranker_inputs(pts)
            for c in np.unique(owner):
                rows = np.flatnonzero(owner == c)
                xs.append(inputs[rows])
                ys.append(np.log(np.maximum(err[rows], 1e-9)))
        k = max(len(y) for y in ys)
        self.x = np.zeros((len(xs), k, *xs[0].shape[1:]), np.float32)
        self.y = np.zeros((len(ys), k), np.float32)
        self.mask = np.zeros((len(ys), k), bool)
        for i, (x, y) in enumerate(zip(xs, ys)):
            self.x[i, : len(y)], self.y[i, : len(y)], self.mask[i, : len(y)] = x, y, True
        self.y[~self.mask] = 0.0

    def __len__(self) -> int:
        return len(self.y)


def _loss(net: RankerNet, x: torch.Tensor, y: torch.Tensor, mask: torch.Tensor, choice_weight: float) -> torch.Tensor:
    c, k = y.shape
    s = net(x.reshape(c * k, *x.shape[2:])).reshape(c, k)
    m = mask.float()
    count = m.sum(1, keepdim=True)
    centred_s = s - (s * m).sum(1, keepdim=True) / count
    centred_y = y - (y * m).sum(1, keepdim=True) / count
    regression = (((centred_s - centred_y) ** 2) * m).sum() / m.sum()
    neg = torch.finfo(s.dtype).min / 2
    target = torch.softmax(torch.where(mask, -y / TEMPERATURE, neg), dim=1)
    log_p = torch.log_softmax(torch.where(mask, -s / TEMPERATURE, neg), dim=1)
    choice = -(target * torch.where(mask, log_p, 0.0)).sum(1).mean()
    return regression + choice_weight * choice


def pick_ratios(scores: np.ndarray, y: np.ndarray, mask: np.ndarray, reads: int = 2) -> dict[str, float]:
    """How close the candidates a ranker keeps come, against the best of all: mean error of the kept (the best of
    the `reads` lowest scores) ÷ mean of the best, as the tables measure sets; and the first pick's."""
    err = np.where(mask, np.exp(y), np.inf)
    order = np.argsort(np.where(mask, scores, np.inf), axis=1)
    best = err.min(1).mean()
    rows = np.arange(len(err))[:, None]
    return {
        "first": float(err[rows[:, 0], order[:, 0]].mean() / best),
        f"best_of_{reads}": float(err[rows, order[:, :reads]].min(1).mean() / best),
    }


# ----------------------------------------------------------------------------------------------- training


def train_ranker(
    labels_dir: str | Path,
    out_dir: str | Path,
    *,
    time_budget: float,
    resume: bool = False,
    init_from: str | Path | None = None,
    lr: float = 2e-3,
    choice_weight: float = CHOICE_WEIGHT,
    batch_curves: int = 64,
    seed: int = 0,
    say: Callable[[str], None] = print,
) -> Path:
    """Train a ranker on every labels-*.npz in `labels_dir` for `time_budget` seconds (learning rate cosine over
    the budget), holding out every VAL_EVERY-th curve (in the files' order, so labels added later keep the split);
    `ranker-last.pt` (atomic, each epoch) lets `resume` carry on where a run stopped, with the time it had left;
    `ranker-best.pt` keeps the epoch whose held-out picks came closest. `init_from`: a new run starting from a
    ranker checkpoint's weights. Returns the best checkpoint's path."""
    files = sorted(Path(labels_dir).glob("labels-*.npz"))
    if not files:
        raise FileNotFoundError(f"{labels_dir}: no labels-*.npz (curve-vae ranker label writes them)")
    data = Labels(files)
    held = np.arange(len(data)) % VAL_EVERY == 0
    val, train = np.flatnonzero(held), np.flatnonzero(~held)
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    torch.manual_seed(seed)
    rng = np.random.default_rng(seed)
    last, best_path = out / "ranker-last.pt", out / "ranker-best.pt"
    net, opt, state = _start(last if resume else None, init_from, lr, time_budget, say)
    run = {  # how the kept checkpoint was trained: export writes it into the manifest
        "curves": len(train),
        "held_out_curves": len(val),
        "label_files": [f.name for f in files],
        "lr": lr,
        "choice_weight": choice_weight,
        "seed": seed,
        "init_from": str(init_from) if init_from is not None else None,
    }
    tensors = tuple(torch.from_numpy(a) for a in (data.x, data.y, data.mask))
    start = time.monotonic() - state["spent"]
    while time.monotonic() - start < time_budget:
        loss = _epoch(net, opt, tensors, rng.permutation(train), batch_curves, choice_weight, lr, start, time_budget)
        state["epoch"] += 1
        state["spent"] = time.monotonic() - start
        ratios = pick_ratios(_scores(net, data.x[val]), data.y[val], data.mask[val])
        say(
            f"epoch {state['epoch']}: loss {loss:.4f}, held-out picks {ratios['first']:.3f}× the best "
            f"(best of two: {ratios['best_of_2']:.3f}×), {state['spent']:.0f}/{time_budget:.0f} s"
        )
        if ratios["best_of_2"] < state["best"]:
            state["best"] = ratios["best_of_2"]
            trained = {**run, "epoch": state["epoch"], "seconds": round(state["spent"], 1)}
            best_ck = {"model": net.state_dict(), "ratios": ratios, "epoch": state["epoch"], "trained": trained}
            atomic_save(best_ck, best_path)
        atomic_save({"model": net.state_dict(), "optimizer": opt.state_dict(), "state": state}, last)
    return best_path


def _start(
    last: Path | None, init_from: str | Path | None, lr: float, time_budget: float, say: Callable[[str], None]
) -> tuple[RankerNet, torch.optim.Optimizer, dict[str, Any]]:
    """The net, its optimiser and the run's state: resumed from `last` where it exists, else new (from
    `init_from`'s weights if given)."""
    net = RankerNet()
    if init_from is not None:
        net.load_state_dict(torch.load(init_from, map_location="cpu", weights_only=False)["model"])
    opt = torch.optim.AdamW(net.parameters(), lr=lr, weight_decay=1e-4)
    state: dict[str, Any] = {"epoch": 0, "spent": 0.0, "best": float("inf")}
    if last is not None and last.exists():
        ck = torch.load(last, map_location="cpu", weights_only=False)
        net.load_state_dict(ck["model"])
        opt.load_state_dict(ck["optimizer"])
        state = ck["state"]
        say(f"resumed at epoch {state['epoch']}, {state['spent']:.0f} s of {time_budget:.0f} spent")
    return net, opt, state


def _epoch(
    net: RankerNet,
    opt: torch.optim.Optimizer,
    tensors: tuple[torch.Tensor, ...],
    order: np.ndarray,
    batch_curves: int,
    choice_weight: float,
    lr: float,
    start: float,
    time_budget: float,
) -> float:
    """One pass over the training curves in `order`, the learning rate cosine in the time spent; the last loss."""
    x, y, mask = tensors
    net.train()
    loss = torch.zeros(())
    for batch in np.array_split(order, max(1, len(order) // batch_curves)):
        frac = min((time.monotonic() - start) / time_budget, 1.0)
        for g in opt.param_groups:
            g["lr"] = lr * 0.5 * (1 + np.cos(np.pi * frac))
        b = torch.from_numpy(batch)
        loss = _loss(net, x[b], y[b], mask[b], choice_weight)
        opt.zero_grad()
        loss.backward()
        opt.step()
    return float(loss.item())


def _scores(net: RankerNet, x: np.ndarray) -> np.ndarray:
    net.eval()
    c, k = x.shape[:2]
    with torch.no_grad():
        return net(torch.from_numpy(x.reshape(c * k, *x.shape[2:]))).numpy().reshape(c, k)


# ----------------------------------------------------------------------------------------------- export


def export_ranker(
    checkpoint: str | Path,
    model_dir: str | Path,
    *,
    meta: dict[str, Any] | None = None,
    default: bool = True,
    version: str | None = None,
) -> Path:
    """Write the checkpoint's net as `ranker.onnx` in `model_dir` (taking the model's points, any number of
    candidates) and name it in the manifest with how it was trained and how it measured (both written atomically).
    `default`: the model's reading becomes pose "learned" (else it stays as it was and "learned" is there to ask
    for); `version`: the model's new version. A `ranker.npz` in place of the checkpoint (the numpy weights models
    before 0.14.0 shipped) is converted: what the manifest said of it is kept, and its reading. Returns the graph's
    path."""
    root = Path(model_dir)
    manifest = json.loads((root / "manifest.json").read_text())
    if Path(checkpoint).suffix == ".npz":
        net = RankerNet.from_weights(read_weights(checkpoint, RANKER_KIND, "a reading ranker"))
        kept = {k: v for k, v in (manifest.get("ranker") or {}).items() if k not in ("file", "kind")}
        entry = {**kept, **(meta or {})}
        default = False
    else:
        ck = torch.load(checkpoint, map_location="cpu", weights_only=False)
        net = RankerNet()
        net.load_state_dict(ck["model"])
        entry = {**(meta or {}), "held_out": ck.get("ratios"), "trained": ck.get("trained")}
    changes: dict[str, Any] = {"reading": {"pose": "learned", "spacing": "search"}} if default else {}
    if version is not None:
        changes["version"] = version
    example = torch.zeros(2, 4, int(manifest["n_points"]))
    return write_part(root, "ranker", RANKER_KIND, net, example, entry, changes=changes)
