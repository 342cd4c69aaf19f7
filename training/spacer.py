"""The spacing guesser: a small network that tells, from a curve's shape alone, the parameter each of its points would
have on one of the paper's splines, so that the natural fit (geometry.natural) starts there and needs a few steps
from one guess where it otherwise scouts nine starts (reading pose "learned"; inference.spacer runs it in onnxruntime).

    paper curve as a caller's polyline --by arc length--> (GRID, 2) --spacer_inputs--> the net --> (GRID,) parameters
        loss: L1 against the generator's own parameters at those points (known exactly: nothing to label)

The curves are drawn afresh for every step from `seed` and the step's number, mirrored and reversed at random, so
a resumed run sees what an unbroken one would; a fixed held-out set (its own seed) measures each checkpoint.
Training is time-budgeted and resumable (`spacer-last.pt`, written atomically every EVAL_EVERY steps, with the
time spent); `spacer-best.pt` keeps the step whose held-out error was least. `export_spacer` writes the net as
spacer.onnx beside the model's graphs and names it in the manifest.
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

from curve_vae.errors import InvalidInput
from curve_vae.geometry import random_control_points, sample_bspline
from curve_vae.geometry.frame import arc_fractions
from curve_vae.inference.spacer import GRID, SPACER_KIND, on_grid, spacer_inputs
from curve_vae.training.checkpoint import atomic_save
from curve_vae.training.families import warp
from curve_vae.training.parts import read_weights, write_part

#: Channels of the residual blocks; each block's dilation (two sweeps that together see the whole grid).
CHANNELS = 32
DILATIONS = (1, 2, 4, 8, 16, 32, 1, 2, 4, 8, 16, 32)
#: The block after which the grid's mean is mixed back into every point (the curve as a whole).
MIX_AFTER = len(DILATIONS) // 2 - 1
#: Points each training curve is drawn at before it is sampled as a caller's polyline, and that polyline's points.
DENSE = 2049
POINTS = (40, 400)
#: Held-out curves, and how often (steps) they are measured and the run saved.
HELD_OUT = 1000
EVAL_EVERY = 100


class SpacerNet(nn.Module):
    """(B, 3, GRID) spacer inputs -> (B, GRID) parameters, 0 to 1, rising (inference.spacer's diagram)."""

    def __init__(self) -> None:
        super().__init__()
        c = CHANNELS
        self.inp = nn.Conv1d(3, c, 5, padding=2)
        self.a = nn.ModuleList([nn.Conv1d(c, c, 3, padding=d, dilation=d) for d in DILATIONS])
        self.b = nn.ModuleList([nn.Conv1d(c, c, 1) for _ in DILATIONS])
        self.mix = nn.Linear(c, c)
        self.out = nn.Conv1d(c, 1, 2)

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        h = self.inp(x)
        for i, (a, b) in enumerate(zip(self.a, self.b)):
            h = h + b(torch.relu(a(torch.relu(h))))
            if i == MIX_AFTER:
                h = h + self.mix(h.mean(2))[..., None]
        step = torch.softmax(self.out(torch.relu(h))[:, 0], dim=1)
        return torch.cat([torch.zeros_like(step[:, :1]), torch.cumsum(step, dim=1)], dim=1)

    @classmethod
    def from_weights(cls, weights: dict[str, np.ndarray]) -> SpacerNet:
        """The net of a spacer.npz's weights (inp_w, block0_a_w, …, mix_b, out_b: the numpy form models before
        0.14.0 shipped), so that an old model's guesser converts to ONNX without its checkpoint."""
        if tuple(int(d) for d in weights["dilations"]) != DILATIONS or int(weights["mix_after"]) != MIX_AFTER:
            raise InvalidInput(f"a spacing guesser of dilations {list(weights['dilations'])}; this one has {DILATIONS}")
        net = cls()
        layers = {"inp": "inp", "mix": "mix", "out": "out"}
        for i in range(len(DILATIONS)):
            layers[f"a.{i}"], layers[f"b.{i}"] = f"block{i}_a", f"block{i}_b"
        state = {}
        for key in net.state_dict():  # "a.3.weight" <- block3_a_w
            layer, kind = key.rsplit(".", 1)
            state[key] = torch.from_numpy(weights[f"{layers[layer]}_{kind[0]}"])
        net.load_state_dict(state)
        return net


def paper_examples(rng: np.random.Generator, count: int) -> tuple[np.ndarray, np.ndarray]:
    """`count` of the paper's curves as callers post them — polylines of 40 to 400 points, spaced evenly in the
    parameter, by arc length or at a random warp of it, mirrored and reversed at random: their spacer inputs
    (count, 3, GRID) and the generator's parameters at the grid's points (count, GRID), the polyline's own
    interpolated along its chords (as the guesser's guesses are read at a caller's points)."""
    dense = sample_bspline(random_control_points(rng, count), DENSE)
    sizes = np.exp(rng.uniform(np.log(POINTS[0]), np.log(POINTS[1]), count)).astype(int)
    kind = rng.integers(0, 3, count)  # 0: even in the parameter, 1: by arc length, 2: warped
    back = rng.random(count) < 0.5
    mirror = np.where(rng.random(count) < 0.5, -1.0, 1.0)
    at = np.linspace(0.0, 1.0, GRID)
    every = np.linspace(0.0, 1.0, DENSE)
    polylines, u = [], np.empty((count, GRID), np.float32)
    for i, (c, n) in enumerate(zip(dense, sizes)):
        if kind[i] == 1:
            q = np.interp(np.linspace(0.0, 1.0, n), arc_fractions(c), every)
        elif kind[i] == 2:
            q = warp(rng, 1, n)[0]
        else:
            q = np.linspace(0.0, 1.0, n)
        pts = np.stack([np.interp(q, every, c[:, 0]) * mirror[i], np.interp(q, every, c[:, 1])], axis=1)
        if back[i]:  # a reversed spline is the spline of its reversed control points: its parameter runs 0 to 1
            pts, q = pts[::-1], (1.0 - q)[::-1]
        polylines.append(pts)
        u[i] = np.interp(at, arc_fractions(pts), q)
    return spacer_inputs(on_grid(polylines)), u


def held_out_error(net: SpacerNet, x: np.ndarray, u: np.ndarray) -> dict[str, float]:
    """The net's parameters against the generator's on held-out curves: mean absolute and root mean square."""
    net.eval()
    with torch.no_grad():
        d = net(torch.from_numpy(x)).numpy() - u
    return {"mae": float(np.abs(d).mean()), "rms": float(np.sqrt((d**2).mean()))}


def train_spacer(
    run_dir: str | Path,
    *,
    time_budget: float,
    resume: bool = False,
    lr: float = 1e-3,
    batch: int = 128,
    seed: int = 0,
    say: Callable[[str], None] = print,
) -> Path:
    """Train a spacing guesser for `time_budget` seconds in all (the learning rate cosine over the budget); `resume`
    carries on from RUN_DIR/spacer-last.pt with the time it had left. Returns the best checkpoint's path."""
    out = Path(run_dir)
    out.mkdir(parents=True, exist_ok=True)
    last, best_path = out / "spacer-last.pt", out / "spacer-best.pt"
    torch.manual_seed(seed)
    net = SpacerNet()
    opt = torch.optim.Adam(net.parameters(), lr=lr)
    state: dict[str, Any] = {"step": 0, "spent": 0.0, "best": float("inf"), "seed": seed, "lr": lr, "batch": batch}
    if resume and last.exists():
        ck = torch.load(last, map_location="cpu", weights_only=False)
        net.load_state_dict(ck["model"])
        opt.load_state_dict(ck["optimizer"])
        state = ck["state"]
        say(f"resumed at step {state['step']}, {state['spent']:.0f} s of {time_budget:.0f} spent")
    held_x, held_u = paper_examples(np.random.default_rng([state["seed"], 1 << 30]), HELD_OUT)
    start = time.monotonic() - state["spent"]
    while (spent := time.monotonic() - start) < time_budget:
        for g in opt.param_groups:
            g["lr"] = state["lr"] * 0.5 * (1 + np.cos(np.pi * spent / time_budget))
        net.train()
        x, u = paper_examples(np.random.default_rng([state["seed"], state["step"]]), state["batch"])
        loss = (net(torch.from_numpy(x)) - torch.from_numpy(u)).abs().mean()
        opt.zero_grad()
        loss.backward()
        opt.step()
        state["step"] += 1
        if state["step"] % EVAL_EVERY == 0 or time.monotonic() - start >= time_budget:
            state["spent"] = time.monotonic() - start
            err = held_out_error(net, held_x, held_u)
            say(
                f"step {state['step']}: loss {loss.item():.4f}, held-out parameters off by {err['mae']:.4f} "
                f"(rms {err['rms']:.4f}), {state['spent']:.0f}/{time_budget:.0f} s"
            )
            if err["rms"] < state["best"]:
                state["best"] = err["rms"]
                trained = {"steps": state["step"], "seconds": round(state["spent"], 1), "curves": state["step"] * batch}
                trained |= {"seed": state["seed"], "lr": state["lr"], "batch": state["batch"]}
                atomic_save({"model": net.state_dict(), "held_out": err, "trained": trained}, best_path)
            atomic_save({"model": net.state_dict(), "optimizer": opt.state_dict(), "state": state}, last)
    return best_path


def export_spacer(
    checkpoint: str | Path, model_dir: str | Path, *, meta: dict[str, Any] | None = None, version: str | None = None
) -> Path:
    """Write the checkpoint's net as `spacer.onnx` in `model_dir` and name it in the manifest with how it was
    trained and how it measured (both written atomically); `version`: the model's new version. A `spacer.npz` in place
    of the checkpoint (the numpy weights models before 0.14.0 shipped) is converted, keeping what the manifest said
    of it. Returns the graph's path."""
    root = Path(model_dir)
    if Path(checkpoint).suffix == ".npz":
        net = SpacerNet.from_weights(read_weights(checkpoint, SPACER_KIND, "a spacing guesser"))
        manifest = json.loads((root / "manifest.json").read_text())
        kept = {k: v for k, v in (manifest.get("spacer") or {}).items() if k not in ("file", "kind")}
        entry = {**kept, **(meta or {})}
    else:
        ck = torch.load(checkpoint, map_location="cpu", weights_only=False)
        net = SpacerNet()
        net.load_state_dict(ck["model"])
        entry = {**(meta or {}), "held_out": ck.get("held_out"), "trained": ck.get("trained")}
    changes = {"version": version} if version is not None else {}
    return write_part(root, "spacer", SPACER_KIND, net, torch.zeros(2, 3, GRID), entry, changes=changes)
