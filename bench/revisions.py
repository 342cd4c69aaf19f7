"""Another revision's files beside this checkout's, for the paired benchmarks (bench.paired_fit, bench.paired_parts):
a file's bytes at a revision, and a module of it loaded from there."""

from __future__ import annotations

import importlib.util
import subprocess
import sys
import tempfile
from pathlib import Path
from types import ModuleType

ROOT = Path(__file__).resolve().parents[1]
#: Where a revision's files are written to be loaded (the system's temporary directory).
SCRATCH = Path(tempfile.gettempdir())


def show(revision: str, path: str) -> bytes:
    """The file at `path` (relative to the repository root) as it is at `revision` (git show)."""
    return subprocess.run(["git", "show", f"{revision}:{path}"], cwd=ROOT, capture_output=True, check=True).stdout


def saved(revision: str, path: str) -> Path:
    """The file at `path` as it is at `revision`, written to the scratch directory; its path there."""
    out = SCRATCH / f"{revision.replace('/', '_')}_{path.replace('/', '_')}"
    out.write_bytes(show(revision, path))
    return out


def module_at(revision: str, path: str, name: str, *, register: bool = False) -> ModuleType:
    """The module in `path` as it is at `revision`, named `name`. register: listed in sys.modules under `name` while
    it loads (so that the revision's other modules loaded after it import it), then whatever was there put back."""
    spec = importlib.util.spec_from_file_location(name, saved(revision, path))
    assert spec and spec.loader
    module = importlib.util.module_from_spec(spec)
    kept = sys.modules.get(name)
    if register:
        sys.modules[name] = module
    try:
        spec.loader.exec_module(module)
    finally:
        if register and kept is not None:
            sys.modules[name] = kept
    return module
