"""Files the commands write: atomically (never a half-written file), and never over a user's file without --force.
Curve files in and out are `curve_vae.curvefiles`."""

from __future__ import annotations

import os
import tempfile
from collections.abc import Iterable, Iterator
from contextlib import contextmanager
from pathlib import Path

import numpy as np

from curve_vae.errors import InvalidInput


def refuse_overwrite(path: str | Path, force: bool, flag: str = "-o") -> None:
    """Stop before any work when `path` exists and the user did not pass --force: nothing of theirs is replaced."""
    if str(path) != "-" and Path(path).exists() and not force:
        raise InvalidInput(f"{path} exists and is left as it is: pass --force to replace it, or give another {flag}")


def write_npy_chunks(path: str, shape: tuple[int, ...], chunks: Iterable[np.ndarray]) -> None:
    """A float32 .npy of `shape` written chunk by chunk (memory bounded by one chunk), in place when complete."""
    from curve_vae.npy import npy_chunks

    tmp = Path(path + ".tmp")
    try:
        with open(tmp, "wb") as f:
            for block in npy_chunks(shape, chunks):
                f.write(block)
        tmp.replace(path)
    finally:
        tmp.unlink(missing_ok=True)


# ------------------------------------------------- atomic output: never a half-written file


@contextmanager
def atomic_path(path: str | Path) -> Iterator[Path]:
    """Yield a temporary path beside `path`; on success rename it over `path` (mode 0644).

    On any error the temporary file is removed and `path` keeps its previous content.
    """
    path = Path(path)
    _folder_for(path)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    os.close(fd)
    try:
        yield Path(tmp)
        os.chmod(tmp, 0o644)
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def _folder_for(path: Path) -> None:
    """Make `path`'s folder; where a file stands in its way, say so (not "[Errno 17] File exists")."""
    for above in [path.parent, *path.parent.parents]:
        if above.exists():
            if not above.is_dir():
                raise NotADirectoryError(f"cannot write {path}: {above} is a file, not a folder")
            break
    path.parent.mkdir(parents=True, exist_ok=True)


def atomic_write_text(path: str | Path, text: str) -> None:
    with atomic_path(path) as tmp:
        tmp.write_text(text)
