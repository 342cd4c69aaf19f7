"""inference.model.graphs: a cancelled request stops at its next graph run."""

from __future__ import annotations

import pytest

from curve_vae.inference.model.graphs import Cancelled, CancelToken, cancellable, checkpoint
from tests.helpers import bspline_curves


def test_checkpoints_are_free_outside_and_raise_once_cancelled_inside():
    checkpoint()  # no token: nothing happens
    token = CancelToken()
    with cancellable(token):
        checkpoint()
        token.cancel("the client disconnected")
        with pytest.raises(Cancelled, match="the client disconnected"):
            checkpoint()
    checkpoint()  # the block is over: the thread's token is gone
    token.cancel("again")
    assert token.reason == "the client disconnected"  # the first reason stays


def test_a_cancelled_reconstruction_stops_between_graph_runs(model_dir):
    from curve_vae.inference.runtime import CurveRuntime

    rt = CurveRuntime.load(model_dir, providers="cpu", intra_op_threads=1, batch_size=4, cache_bytes=0)
    token = CancelToken()
    runs: list[int] = []
    run = rt.graphs._run_graph

    def counted(*args):
        runs.append(1)
        if len(runs) == 2:
            token.cancel("past CURVE_VAE_REQUEST_TIMEOUT")
        return run(*args)

    rt.graphs._run_graph = counted  # type: ignore[method-assign]
    with cancellable(token), pytest.raises(Cancelled):
        rt.reconstruct(list(bspline_curves(40, 50)))  # 10 encoder runs of 4 curves, then 10 decoder runs
    assert len(runs) == 2  # cancelled during the first run: the second stopped at its checkpoint, none after
