"""Every error curve-vae raises on purpose, under one root, in the manner of httpx's: catch `CurveVaeError` for all
of them, or a branch for one kind. The modules that raise them keep their own names (`InputError`, `ModelLoadError`,
`ApiError`, …), each a subclass of its branch here; the branches keep the builtin bases they had (an input error is
still a `ValueError`), so code that caught those before still does.

    CurveVaeError
    ├── InvalidInput (ValueError)   inference.errors.InputError, geometry.adapt.BeyondFloat32, curvefiles CurveFileError
    ├── ModelError (RuntimeError)   inference.model.manifest.ModelLoadError
    ├── CancelledWork               inference.model.graphs.Cancelled
    ├── ProtocolError               service.oip.OipError
    └── ClientError (RuntimeError)  client.errors.ApiError, RetriesExhausted

Raise these, not bare builtins, for anything a user can cause: `curve-vae` prints a CurveVaeError (or an OSError: a
file it cannot open or write) as one line and exits 2, and lets anything else, a bug, show its traceback.

This module imports nothing of the project: every layer, geometry included, may use it.
"""

from __future__ import annotations


class CurveVaeError(Exception):
    """The root: an error curve-vae raises on purpose, with a message that says what is wrong and what to do."""


class InvalidInput(CurveVaeError, ValueError):
    """Input the project cannot take (a request's curves, a curve file, a value out of range); the message names it."""


class ModelError(CurveVaeError, RuntimeError):
    """A model directory, or the runtime that would run it, that cannot serve."""


class CancelledWork(CurveVaeError):
    """Work that was abandoned: its client went away, or it passed its time limit."""


class ProtocolError(CurveVaeError):
    """A request that breaks a wire protocol the service speaks (the Open Inference Protocol)."""


class ClientError(CurveVaeError, RuntimeError):
    """What a client call raises when the service says no, or cannot be reached."""
