"""Progress bars for commands that run longer than a few seconds: on a terminal only, off with --no-progress.

A bar counts the work actually planned (curves to write, seconds of a time budget), so it ends where the
command does. Pipes and CI logs get no bar, only the commands' own one-line summaries.
"""

from __future__ import annotations

import sys
from collections.abc import Iterable, Iterator, Sized
from typing import Any

from tqdm import tqdm


def shown(no_progress: bool = False) -> bool:
    """Whether to draw bars: not asked off, and stderr is a terminal."""
    return not no_progress and sys.stderr.isatty()


def counted(chunks: Iterable[Sized], progress: tqdm) -> Iterator[Any]:
    """The chunks, counting the rows of each on `progress` as it passes."""
    for chunk in chunks:
        progress.update(len(chunk))
        yield chunk


def bar(total: float, desc: str, *, enabled: bool, unit: str = "curve", **options: Any) -> tqdm:
    """A tqdm bar on stderr; a silent one (same methods) where bars are off."""
    return tqdm(total=total, desc=desc, unit=unit, disable=not enabled, dynamic_ncols=True, leave=False, **options)
