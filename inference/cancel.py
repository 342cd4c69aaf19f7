"""Abandoned work stops: a request whose client has gone, or which ran past its time limit, is cancelled, and the
inference thread running it stops at its next checkpoint — before each run of a graph, between chunks — instead of
computing to the end.

    token = CancelToken()
    with cancellable(token):      # on the inference thread
        runtime.reconstruct(...)  # raises Cancelled at the next checkpoint once token.cancel() is called

`checkpoint()` is a no-op outside `cancellable`, so offline callers (the command line, training's evaluation) pay
nothing for it.
"""

from __future__ import annotations

import threading
from collections.abc import Iterator
from contextlib import contextmanager

from curve_vae.errors import CancelledWork


class Cancelled(CancelledWork):
    """The work was abandoned: its client went away, or it passed its time limit."""


class CancelToken:
    """Set from any thread (the event loop's), read on the inference thread."""

    def __init__(self) -> None:
        self._event = threading.Event()
        self.reason = ""

    def cancel(self, reason: str) -> None:
        if not self._event.is_set():
            self.reason = reason
            self._event.set()

    @property
    def cancelled(self) -> bool:
        return self._event.is_set()

    def check(self) -> None:
        if self._event.is_set():
            raise Cancelled(self.reason)


_local = threading.local()


@contextmanager
def cancellable(token: CancelToken) -> Iterator[CancelToken]:
    """Make `token` the calling thread's for the block: `checkpoint()` raises Cancelled once it is cancelled."""
    before = getattr(_local, "token", None)
    _local.token = token
    try:
        yield token
    finally:
        _local.token = before


def checkpoint() -> None:
    """Raise Cancelled if the calling thread's work was cancelled (a no-op outside `cancellable`)."""
    token = getattr(_local, "token", None)
    if token is not None:
        token.check()
