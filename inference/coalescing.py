"""Concurrent small requests read as one batch: the default reading of a curve costs less a curve in company (16 ms
alone, 10 ms in a batch of eight on this project's CPU: the natural-spacing fit, the ranker and the placement are
vectorised over a batch, and their per-call overhead is paid once), so requests that queue for an inference thread
at the same moment are read together and each gets its own part back.

Flat combining, without waiting for company: every request registers its job, then queues for an inference thread
as before. The thread that picks a job up runs it together with every other registered job of the same options not
yet taken (up to `max_curves` curves); a job already taken by another thread's batch waits for it, and while it
waits its thread runs the next batch of untaken jobs, if any. A request to an idle server runs alone at once —
nothing is added to its latency — and under load the batches grow with the queue.

- Only jobs with equal options (the reading, `n_points`) share a batch; a job larger than `max_curves` runs alone.
- Right after a batch ends its clients are answered and ask again within a few milliseconds: the next batch waits
  up to `hold` (5 ms) for as many jobs as the last had, instead of starting with the first to come back while the
  rest queue behind it (under load, single-curve batches gave way to batches of the connections' number).
- At most `readers` batches are read at once (the service: the CPUs of a worker, so one on 2 cores with 2 workers):
  a thread that would start another waits, and the jobs queueing meanwhile make the next batch larger. Two batches
  sharing one core cost more than one of both (measured: single-curve requests on 16 connections, 132 requests/s
  with a batch per inference thread, 156 with one per worker; docs/BENCHMARKS.md).
- A failing batch (a bad curve in one job) is run again job by job, so an error names its own request's curve.
- A batch is cancelled only when every job in it is (each job's token, inference.graphs); a job abandoned before it
  was taken is never read.
- Answers equal the lone request's to rounding: onnxruntime may round a batch's rows differently, so where two
  candidate readings tie to float32 rounding either may be kept.
"""

from __future__ import annotations

import functools
import threading
import time
from collections.abc import Callable, Hashable, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Generic, TypeAlias, TypeVar, cast

import numpy as np

from curve_vae.inference.graphs import Cancelled, CancelToken, cancellable
from curve_vae.inference.reading import Reading
from curve_vae.inference.results import Encoding, Reconstruction, split_encoding, split_reconstruction

if TYPE_CHECKING:
    from curve_vae.inference.runtime import CurveRuntime

R = TypeVar("R")


class _Joint(CancelToken):
    """Cancelled once every one of `tokens` is: a batch goes on while any of its requests still wants an answer."""

    def __init__(self, tokens: Sequence[CancelToken]) -> None:
        super().__init__()
        self.tokens = tokens

    @property
    def cancelled(self) -> bool:
        return all(t.cancelled for t in self.tokens)

    def check(self) -> None:
        if self.cancelled:
            raise Cancelled(self.tokens[0].reason)


@dataclass(eq=False)
class Job(Generic[R]):
    """One request's curves and options, and, once read, its result or error."""

    key: Hashable
    curves: Sequence[np.ndarray]
    token: CancelToken = field(default_factory=CancelToken)
    taken: bool = False
    done: threading.Event = field(default_factory=threading.Event)
    result: R | None = None
    error: BaseException | None = None

    def finish(self, result: R | None = None, error: BaseException | None = None) -> None:
        self.result, self.error = result, error
        self.done.set()


class Coalescer(Generic[R]):
    """Jobs of equal keys read together by `read(key, curves)`, whose result `split(result, sizes)` cuts into each
    job's part (in order)."""

    def __init__(
        self,
        read: Callable[[Hashable, list[np.ndarray]], R],
        split: Callable[[R, list[int]], list[R]],
        *,
        max_curves: int = 32,
        readers: int | None = None,
        hold: float = 0.005,
        observe: Callable[[int, int], None] | None = None,
    ) -> None:
        self._read, self._split, self.max_curves = read, split, max_curves
        self.readers = readers  # batches read at once (None: one per thread that asks)
        self.hold = hold  # seconds a batch may wait, right after one ended, for as many jobs as it had
        self._reading = 0
        self._ended, self._last = -1e9, 0  # when the last batch ended (time.monotonic), and its jobs
        self._observe = observe  # (jobs, curves) of each batch run: the service's histogram
        self._changed = threading.Condition()  # a job registered or a batch finished
        self._pending: list[Job[R]] = []

    def submit(self, key: Hashable, curves: Sequence[np.ndarray], token: CancelToken | None = None) -> Job[R]:
        """Register a job (on the event loop, before it queues for an inference thread)."""
        job: Job[R] = Job(key, curves, token or CancelToken())
        with self._changed:
            self._pending.append(job)
            self._changed.notify_all()
        return job

    def forget(self, job: Job[R]) -> None:
        """A job whose request has ended (answered, timed out, abandoned) leaves the register."""
        with self._changed:
            if job in self._pending:
                self._pending.remove(job)

    def result(self, job: Job[R]) -> R:
        """`job`'s result (on an inference thread): read now with the other untaken jobs of its key, or waited for
        while this thread reads the batches of jobs still untaken."""
        while True:
            with self._changed:
                batch = self._next(job)
            if batch is None:
                break
            try:
                self._run(batch)
            finally:
                for j in batch:  # an error past Exception (KeyboardInterrupt) still ends every job of the batch
                    if not j.done.is_set():
                        j.finish(error=Cancelled("the batch reading this request stopped"))
                with self._changed:
                    self._reading -= 1
                    self._ended, self._last = time.monotonic(), len(batch)
                    self._changed.notify_all()
        if job.error is not None:
            raise job.error
        assert job.result is not None
        return job.result

    def _live(self) -> list[Job[R]]:
        return [j for j in self._pending if not j.taken and not j.token.cancelled]

    def _next(self, job: Job[R]) -> list[Job[R]] | None:
        """What the thread serving `job` reads next (under the lock): `job` with the untaken jobs of its key; once
        another batch has taken it, the oldest untaken job's batch, or nothing until one comes; None once it is
        done."""
        while not job.done.is_set():
            if not job.taken and job.token.cancelled:  # abandoned: read alone, which stops at once
                return self._take(job, alone=True)
            if self.readers is None or self._reading < self.readers:
                held = self._held()
                if held > 0:
                    self._changed.wait(held)
                    continue
                if not job.taken:
                    return self._take(job)
                live = self._live()
                if live:
                    return self._take(live[0])
            self._changed.wait()
        return None

    def _held(self) -> float:
        """Seconds a new batch should still wait (under the lock): right after a batch ended, its requests' clients
        are being answered and will ask again, so a batch started at once would be one of the first to come back and
        the rest would wait for it. Up to `hold` after a batch ended, until as many jobs wait as it had."""
        left = self._ended + self.hold - time.monotonic()
        return left if left > 0 and len(self._live()) < self._last else 0.0

    def _take(self, first: Job[R], *, alone: bool = False) -> list[Job[R]]:
        """`first` and (unless alone) the untaken jobs of its key, up to max_curves curves, taken off the register."""
        batch, count = [first], len(first.curves)
        for j in [] if alone else self._live():
            if j is not first and j.key == first.key and count + len(j.curves) <= self.max_curves:
                batch.append(j)
                count += len(j.curves)
        self._reading += 1
        for j in batch:
            j.taken = True
            if j in self._pending:  # `first` may have been forgotten (its request ended): it is read alone
                self._pending.remove(j)
        return batch

    def _run(self, batch: list[Job[R]]) -> None:
        if len(batch) > 1:
            curves = [c for j in batch for c in j.curves]
            try:
                with cancellable(_Joint([j.token for j in batch])):
                    parts = self._split(self._read(batch[0].key, curves), [len(j.curves) for j in batch])
            except Exception:
                pass  # job by job below: an error names its own request's curve
            else:
                if self._observe is not None:
                    self._observe(len(batch), len(curves))
                for j, part in zip(batch, parts):
                    j.finish(part)
                return
        for j in batch:
            try:
                with cancellable(j.token):
                    j.token.check()
                    part = self._read(j.key, list(j.curves))
            except Exception as e:
                j.finish(error=e)
            else:
                if self._observe is not None:
                    self._observe(1, len(j.curves))
                j.finish(part)


#: What a runtime's coalescer reads: `/encode`'s and `/reconstruct`'s results.
Read: TypeAlias = Encoding | Reconstruction


def runtime_coalescer(
    runtime: CurveRuntime,
    *,
    max_curves: int = 32,
    readers: int | None = None,
    observe: Callable[[int, int], None] | None = None,
) -> Coalescer[Read]:
    """A coalescer of `runtime.encode` and `runtime.reconstruct` calls: jobs keyed `(kind, reading, n_points)`,
    kind "encode" or "reconstruct" (`encode_key`, `reconstruct_key`)."""

    def split(result: Read, sizes: list[int]) -> list[Read]:
        parts = split_encoding(result, sizes) if isinstance(result, Encoding) else split_reconstruction(result, sizes)
        return list[Read](parts)  # a list of one kind, typed as either

    read = functools.partial(read_alone, runtime)
    return Coalescer(read, split, max_curves=max_curves, readers=readers, observe=observe)


def read_alone(runtime: CurveRuntime, key: Hashable, curves: Sequence[np.ndarray]) -> Read:
    """What a job of `key` (`encode_key`, `reconstruct_key`) reads, without company."""
    kind, reading, n_points = cast(tuple[str, Reading, int | None], key)  # encode_key's or reconstruct_key's
    if kind == "encode":
        return runtime.encode(curves, reading)
    return runtime.reconstruct(curves, reading, n_points=n_points)


def encode_key(reading: Reading) -> tuple[str, Reading, None]:
    return ("encode", reading, None)


def reconstruct_key(reading: Reading, n_points: int | None) -> tuple[str, Reading, int | None]:
    return ("reconstruct", reading, n_points)
