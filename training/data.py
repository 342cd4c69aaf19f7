"""The curve data set (paper §3.1): random open cubic B-splines, sampled, split and cached."""

from __future__ import annotations

import hashlib
import json
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np

from curve_vae.errors import InvalidInput
from curve_vae.files import atomic_path
from curve_vae.geometry import random_control_points, sample_bspline, self_intersects

FORMAT_VERSION = 1
MIXES = ("paper", "broad", "files")


@dataclass(frozen=True)
class DataConfig:
    n_train: int = 70_000  # paper §3.1
    n_val: int = 2_000  # model selection / early stopping; never used for the reported MSE
    n_test: int = 1_000  # paper Table 1 evaluates on 1,000 curves
    seed: int = 0  # one seed draws all three splits, in this order
    n_ctrl: int = 10  # control points per curve, one per angular sector
    n_points: int = 161  # samples per curve, evenly spaced in the curve parameter
    radius: float = 64.0  # control points lie in this circle ...
    center: tuple[float, float] = (64.0, 64.0)  # ... centred in the 128×128 plane
    # "paper": every split is the paper's curves. "broad": training and validation curves come from the broad
    # mix of training/mixes.py (any spacing, shapes beyond the paper's, in the service's pose and frame);
    # the test split stays the paper's, the one eq. 4's MSE is reported on. "files": a user's own curves, read
    # from `source` (training/mixes.own_curves): split by curve, the training curves posed n_train times.
    mix: str = "paper"
    source: str = ""  # mix "files": a curve file, or a directory of .npy/.csv/.json/.dat files
    # mix "broad": the version of its definition (training.mixes.MIX_VERSION), set by default; 0 otherwise
    mix_version: int = 0
    # mix "broad": also keep each training and validation curve evenly in its own parameter, in the same pose
    # (its "twin", training.families.draw_family), for training with match "twin"
    twins: bool = False

    def __post_init__(self) -> None:
        if self.mix not in MIXES:
            raise InvalidInput(f"mix must be one of {', '.join(MIXES)}, got {self.mix!r}")
        if self.mix == "broad" and not self.mix_version:
            from curve_vae.training.mixes import MIX_VERSION

            object.__setattr__(self, "mix_version", MIX_VERSION)
        elif self.mix != "broad" and self.mix_version:
            raise InvalidInput('mix_version belongs to mix "broad" only')
        if self.twins and self.mix != "broad":
            raise InvalidInput('twins belong to mix "broad" only: its families know their own parameter')
        if (self.mix == "files") != bool(self.source):
            raise InvalidInput('a data source (--curves PATH) goes with mix "files", and only with it')


def generate_curves(
    count: int,
    seed: int,
    *,
    n_ctrl: int = 10,
    n_points: int = 161,
    radius: float = 64.0,
    center: tuple[float, float] = (64.0, 64.0),
    chunk: int = 8192,
    skip: int = 0,
) -> tuple[np.ndarray, np.ndarray]:
    """`count` non-self-intersecting curves (count, n_points, 2) float32 and their control points.

    Draws in chunks and rejects self-intersecting curves, so the result for a given seed
    does not depend on how many are asked for beyond a prefix: the first k of a request for
    n > k curves are the curves a request for k returns. `skip` leaves out the first `skip`
    curves, drawn but not kept: the curves `skip` to `skip + count` of a longer request (the
    paper's 1,000 test curves follow 72,000 others: 0.7 s against 1.2-2.4 s, and a hundredth
    of the memory).
    """
    rng = np.random.default_rng(seed)
    curves, ctrls, seen = [], [], 0
    while seen < skip + count:
        ctrl = random_control_points(rng, chunk, n_ctrl=n_ctrl, radius=radius, center=center)
        pts = sample_bspline(ctrl, n_points)
        ok = np.flatnonzero(~np.asarray(self_intersects(pts)))  # a batch's answer is an array
        kept = ok[max(skip - seen, 0) : skip + count - seen]
        curves.append(pts[kept].astype(np.float32))
        ctrls.append(ctrl[kept].astype(np.float32))
        seen += len(ok)
    return np.concatenate(curves), np.concatenate(ctrls)


def paper_test_curves(config: DataConfig) -> tuple[np.ndarray, np.ndarray]:
    """The broad mix's test split and its control points: the paper data set's own test curves (DataConfig()'s
    sizes, this seed), so eq. 4's MSE is measured on the paper's test curves whatever the mix and its size."""
    return _paper_curves(config, config.n_test, skip=DataConfig().n_train + config.n_val)


def _paper_curves(config: DataConfig, count: int, *, skip: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """`count` curves of the paper's generator with `config`'s seed and parameters, after its first `skip`."""
    return generate_curves(
        count,
        config.seed,
        n_ctrl=config.n_ctrl,
        n_points=config.n_points,
        radius=config.radius,
        center=config.center,
        skip=skip,
    )


@dataclass(frozen=True)
class CurveDataset:
    """The three splits as (n, n_points, 2) float32 arrays in the 128×128 plane."""

    config: DataConfig
    train: np.ndarray
    val: np.ndarray
    test: np.ndarray
    test_ctrl: np.ndarray  # control points of the test curves, for B-spline comparisons
    train_twins: np.ndarray | None = None  # with config.twins: each training curve evenly in its own parameter
    val_twins: np.ndarray | None = None

    @classmethod
    def generate(cls, config: DataConfig, *, workers: int = 1) -> CurveDataset:
        """The data set of `config`; the broad mix is drawn by `workers` processes (the same data however many)."""
        if config.mix == "files":
            from curve_vae.training.mixes import own_curves

            train, val, test = own_curves(config.source, config.n_train, config.seed, n_points=config.n_points)
            return cls(config, train, val, test, np.zeros((len(test), 0, 2), np.float32))
        a, b = config.n_train, config.n_train + config.n_val
        if config.mix == "broad":
            from curve_vae.training.mixes import broad_mix

            curves, ctrl = paper_test_curves(config)
            mixed = broad_mix(
                b,
                config.seed + 1,
                n_points=config.n_points,
                workers=workers,
                version=config.mix_version,
                twins=config.twins,
            )
            if config.twins:
                (drawn, even) = mixed
                return cls(config, drawn[:a], drawn[a:b], curves, ctrl, even[:a], even[a:b])
            return cls(config, mixed[:a], mixed[a:b], curves, ctrl)
        curves, ctrl = _paper_curves(config, config.n_train + config.n_val + config.n_test)
        return cls(config, curves[:a], curves[a:b], curves[b:], ctrl[b:])

    def save(self, path: str | Path) -> None:
        """Write atomically: a crash never leaves a half-written cache behind."""
        meta = json.dumps({"format_version": FORMAT_VERSION, "config": asdict(self.config)})
        with atomic_path(path) as tmp, open(tmp, "wb") as f:
            twins: dict[str, np.ndarray] = {}
            if self.train_twins is not None:
                assert self.val_twins is not None, "twins come in pairs: train and val"
                twins = {"train_twins": self.train_twins, "val_twins": self.val_twins}
            np.savez(
                f,
                meta=np.array(meta),
                train=self.train,
                val=self.val,
                test=self.test,
                test_ctrl=self.test_ctrl,
                **twins,  # type: ignore[arg-type]  # numpy's stub: mypy checks **arrays against allow_pickle: bool too
            )

    @classmethod
    def load(cls, path: str | Path) -> CurveDataset:
        with np.load(path, allow_pickle=False) as z:
            meta = json.loads(str(z["meta"]))
            if meta.get("format_version") != FORMAT_VERSION:
                raise InvalidInput(
                    f"{path}: data set format {meta.get('format_version')}, "
                    f"expected {FORMAT_VERSION}; regenerate it with `curve-vae dataset`"
                )
            cfg = meta["config"]
            cfg["center"] = tuple(cfg["center"])
            cfg.setdefault("mix_version", 1 if cfg.get("mix") == "broad" else 0)  # written before versions
            twins = (z["train_twins"], z["val_twins"]) if "train_twins" in z else (None, None)
            return cls(DataConfig(**cfg), z["train"], z["val"], z["test"], z["test_ctrl"], *twins)


def default_cache(config: DataConfig) -> Path:
    """Where a configuration's data set is cached by default: one file per configuration (data/curves-<digest>.npz),
    so that a cache is never regenerated over, whatever the parameters asked for."""
    described = asdict(config)
    if not config.twins:
        del described["twins"]  # the caches of data sets without twins keep the names they had before twins
    digest = hashlib.sha256(json.dumps(described, sort_keys=True).encode()).hexdigest()[:10]
    return Path("data") / f"curves-{digest}.npz"


def load_or_generate(
    config: DataConfig, cache: str | Path | None, *, say: bool = True, workers: int = 1
) -> CurveDataset:
    """The data set for `config`: from `cache` when it holds exactly that configuration, generated and written there
    when the file does not exist yet (saying where), generated without a file for cache None.

    A file that holds another configuration, or no data set of ours, is never overwritten: ValueError names both.
    """
    if cache is not None and Path(cache).exists():
        try:
            ds = CurveDataset.load(cache)
        except (ValueError, KeyError, OSError) as e:
            raise InvalidInput(
                f"{cache} is not a curve-vae data set ({e}); it is left as it is: give another --data path"
            ) from e
        if ds.config != config:
            mine, theirs = asdict(config), asdict(ds.config)
            diff = ", ".join(f"{k} {theirs[k]} (file) vs {mine[k]} (asked)" for k in mine if mine[k] != theirs[k])
            raise InvalidInput(
                f"{cache} holds a data set of another configuration: {diff}; it is left as it is: give another "
                "--data path, or omit --data for the default cache of each configuration"
            )
        return ds
    ds = CurveDataset.generate(config, workers=workers)
    if cache is not None:
        ds.save(cache)
        if say:
            print(f"generated the data set ({len(ds.train)} / {len(ds.val)} / {len(ds.test)} curves) into {cache}")
    return ds


def load_test_split(config: DataConfig, cache: str | Path | None) -> np.ndarray:
    """The test split of `config`'s data set, without drawing the broad mix's training split (its test curves are
    the paper's, paper_test_curves); other mixes load or generate their whole data set."""
    if config.mix == "broad":
        return paper_test_curves(config)[0]
    return load_or_generate(config, cache).test
