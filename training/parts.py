"""A learned part written beside a model's graphs (the reading ranker, the spacing guesser): its weights as an .npz
of their `kind`, and its entry in the manifest with how it was trained and measured — both written atomically."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np

from curve_vae.files import atomic_path, atomic_write_text
from curve_vae.inference.manifest import file_sha256


def write_part(
    model_dir: str | Path,
    name: str,
    kind: str,
    weights: dict[str, np.ndarray],
    entry: dict[str, Any],
    *,
    changes: dict[str, Any] | None = None,
) -> Path:
    """`weights` as `name`.npz (with `kind`) in `model_dir`, named in its manifest under `name` (file, kind, then
    `entry`) with its sha256; `changes`: other manifest fields set at once (version, reading). Returns its path."""
    root = Path(model_dir)
    path = root / f"{name}.npz"
    with atomic_path(path) as tmp:
        with open(tmp, "wb") as fh:
            # the ignore: numpy's stub, mypy checks **arrays against allow_pickle: bool too
            np.savez(fh, kind=kind, **weights)  # type: ignore[arg-type]
    manifest_path = root / "manifest.json"
    manifest = json.loads(manifest_path.read_text())
    manifest["files"][path.name] = {"sha256": file_sha256(path), "bytes": path.stat().st_size}
    manifest[name] = {"file": path.name, "kind": kind, **entry}
    manifest.update(changes or {})
    atomic_write_text(manifest_path, json.dumps(manifest, indent=2) + "\n")
    return path
