"""Coalescing: requests registered together are read as one batch, each getting its own part back, equal to its
lone reading; only equal options share a batch; a bad job fails alone with its own curve named; an abandoned job is
not read; threads waiting for a batch read the next one meanwhile."""

from __future__ import annotations

import threading
import time

import numpy as np
import pytest

from curve_vae.inference.errors import InputError
from curve_vae.inference.model.graphs import Cancelled
from curve_vae.inference.reading import Reading
from curve_vae.service.deps import Coalescer, encode_key, reconstruct_key, runtime_coalescer

DEFAULT = reconstruct_key(Reading(), None)


@pytest.fixture
def batches():
    return []  # (jobs, curves) of each batch read


@pytest.fixture
def coalescer(runtime, batches):
    return runtime_coalescer(runtime, max_curves=32, observe=lambda jobs, curves: batches.append((jobs, curves)))


def _same(got, alone):
    for a, b in zip(got.curves, alone.curves, strict=True):
        np.testing.assert_allclose(a, b, rtol=1e-4, atol=1e-4 * float(np.ptp(b)))
    np.testing.assert_allclose(got.mse, alone.mse, rtol=1e-3, atol=1e-9)
    np.testing.assert_allclose(got.latents, alone.latents, rtol=1e-4, atol=1e-4)
    assert [(f.mirror, f.reverse, round(f.rotation, 6)) for f in got.frames] == [
        (f.mirror, f.reverse, round(f.rotation, 6)) for f in alone.frames
    ]


def test_registered_jobs_are_read_as_one_batch_each_its_own_part(coalescer, batches, runtime, curves):
    # requests of 1–3 curves, of different lengths, as they queue together
    asked = [[*curves(k, 40 + 10 * i, seed=i)] for i, k in enumerate((1, 3, 2, 1, 2))]
    jobs = [coalescer.submit(DEFAULT, c) for c in asked]
    first = coalescer.result(jobs[0])
    assert batches == [(5, 9)]  # one read for all five
    assert all(j.done.is_set() for j in jobs)
    for c, got in zip(asked, [first, *(coalescer.result(j) for j in jobs[1:])]):
        assert len(got.curves) == len(c) and [len(x) for x in got.curves] == [len(x) for x in c]
        _same(got, runtime.reconstruct(c))
    assert batches == [(5, 9)]  # the others were answered from that read


def test_encodings_too(coalescer, batches, runtime, curves):
    asked = [[*curves(2, 50, seed=1)], [*curves(1, 60, seed=2)]]
    jobs = [coalescer.submit(encode_key(Reading()), c) for c in asked]
    got = [coalescer.result(j) for j in jobs]
    assert batches == [(2, 3)]
    for c, enc in zip(asked, got):
        alone = runtime.encode(c)
        np.testing.assert_allclose(enc.mean, alone.mean, rtol=1e-4, atol=1e-4)
        np.testing.assert_allclose(enc.log_var, alone.log_var, rtol=1e-4, atol=1e-4)


def test_only_equal_options_share_a_batch(coalescer, batches, curves):
    keys = [DEFAULT, reconstruct_key(Reading(pose="as_is"), None), DEFAULT, reconstruct_key(Reading(), 20)]
    jobs = [coalescer.submit(k, [curves(1, 40, seed=i)[0]]) for i, k in enumerate(keys)]
    coalescer.result(jobs[0])
    assert batches == [(2, 2)] and jobs[2].done.is_set() and not jobs[1].done.is_set()
    assert len(coalescer.result(jobs[3]).curves[0]) == 20
    assert batches == [(2, 2), (1, 1)]


def test_a_batch_holds_at_most_max_curves(runtime, batches, curves):
    coalescer = runtime_coalescer(runtime, max_curves=4, observe=lambda jobs, n: batches.append((jobs, n)))
    jobs = [coalescer.submit(DEFAULT, [*curves(k, 40, seed=i)]) for i, k in enumerate((3, 2, 1, 6))]
    coalescer.result(jobs[0])
    assert batches == [(2, 4)]  # 3 + 1: the 2 would pass four
    coalescer.result(jobs[3])  # larger than a batch: alone
    assert batches == [(2, 4), (1, 6)]


def test_a_bad_job_fails_alone_naming_its_own_curve(coalescer, batches, curves):
    good = [[*curves(1, 40, seed=k)] for k in range(3)]
    bad = [curves(1, 40, seed=9)[0], np.ones((40, 2))]  # its second curve: every point the same
    jobs = [coalescer.submit(DEFAULT, c) for c in (good[0], bad, good[1], good[2])]
    with pytest.raises(InputError) as e:
        coalescer.result(jobs[1])
    assert e.value.loc[:2] == ("curves", 1)  # its own index, not the batch's (2)
    assert all(len(coalescer.result(j).curves) == 1 for j in (jobs[0], jobs[2], jobs[3]))
    assert batches == [(1, 1), (1, 1), (1, 1)]  # after the batch failed, job by job


def test_an_abandoned_job_is_not_read(coalescer, batches, curves):
    jobs = [coalescer.submit(DEFAULT, [curves(1, 40, seed=k)[0]]) for k in range(3)]
    jobs[1].token.cancel("the client disconnected")
    coalescer.result(jobs[0])
    assert batches == [(2, 2)] and not jobs[1].done.is_set()
    with pytest.raises(Cancelled, match="disconnected"):
        coalescer.result(jobs[1])
    assert batches == [(2, 2)]


def test_a_forgotten_job_still_gets_its_answer(coalescer, batches, curves):
    job = coalescer.submit(DEFAULT, [curves(1, 40)[0]])
    coalescer.forget(job)  # its request ended before its thread came to it
    assert len(coalescer.result(job).curves) == 1 and batches == [(1, 1)]


def test_threads_waiting_for_a_batch_read_the_next():
    # a reading that holds its first batch until told: jobs registered meanwhile are read by the thread whose own
    # job is in that first batch, instead of its idling
    gate, reads = threading.Event(), []

    def read(key, items):
        if not reads:
            reads.append("first")
            assert gate.wait(30)
        else:
            reads.append(list(items))
        return list(items)

    coalescer = Coalescer(read, lambda got, sizes: [got[i - n : i] for n, i in zip(sizes, np.cumsum(sizes))])
    first = [coalescer.submit("k", [f"a{i}"]) for i in range(3)]
    got: dict[str, list] = {}

    def serve(job) -> None:
        got[job.curves[0]] = coalescer.result(job)

    one = threading.Thread(target=serve, args=(first[0],))
    one.start()
    while not reads:  # thread one is reading a0, a1, a2 and waits at the gate
        time.sleep(0.001)
    two = threading.Thread(target=serve, args=(first[1],))
    two.start()  # a1 is taken: this thread waits for it
    later = [coalescer.submit("k", [f"b{i}"]) for i in range(2)]
    deadline = time.monotonic() + 30
    while not all(j.done.is_set() for j in later) and time.monotonic() < deadline:
        time.sleep(0.001)
    assert reads == ["first", ["b0", "b1"]]  # read by thread two while the first batch was still held
    assert not first[1].done.is_set()
    gate.set()
    one.join(30), two.join(30)
    assert got == {"a0": ["a0"], "a1": ["a1"]}
    assert coalescer.result(first[2]) == ["a2"] and [coalescer.result(j) for j in later] == [["b0"], ["b1"]]


def test_threads_at_once_each_get_their_own(coalescer, batches, runtime, curves):
    asked = [[curves(1, 40 + i, seed=i)[0]] for i in range(8)]
    jobs = [coalescer.submit(DEFAULT, c) for c in asked]
    start = threading.Barrier(len(jobs))
    results: dict[int, object] = {}

    def serve(k: int) -> None:
        start.wait()
        results[k] = coalescer.result(jobs[k])

    threads = [threading.Thread(target=serve, args=(k,)) for k in range(len(jobs))]
    for t in threads:
        t.start()
    for t in threads:
        t.join(60)
    assert batches == [(8, 8)]
    for k, c in enumerate(asked):
        _same(results[k], runtime.reconstruct(c))


def test_at_most_readers_batches_at_once():
    # one reader: a thread whose own job was registered after the first batch was taken waits for that batch
    # instead of reading beside it, and its job and those that came meanwhile are read as one batch after it
    gate, reads = threading.Event(), []

    def read(key, items):
        reads.append(list(items))
        if len(reads) == 1:
            assert gate.wait(30)
        return list(items)

    coalescer = Coalescer(read, lambda got, sizes: [got[i - n : i] for n, i in zip(sizes, np.cumsum(sizes))], readers=1)
    first = coalescer.submit("k", ["a"])
    one = threading.Thread(target=coalescer.result, args=(first,))
    one.start()
    while not reads:
        time.sleep(0.001)
    second = coalescer.submit("k", ["b"])
    two = threading.Thread(target=coalescer.result, args=(second,))
    two.start()
    time.sleep(0.05)
    third = coalescer.submit("k", ["c"])
    time.sleep(0.05)
    assert reads == [["a"]] and not second.done.is_set()  # thread two waits for the reader
    gate.set()
    one.join(30), two.join(30)
    assert reads == [["a"], ["b", "c"]] and coalescer.result(third) == ["c"]


def _recording(reads):
    def read(key, items):
        reads.append(list(items))
        return list(items)

    return read


def _cut(got, sizes):
    return [got[i - n : i] for n, i in zip(sizes, np.cumsum(sizes))]


def test_after_a_batch_the_next_waits_for_as_many_requests():
    # right after a batch of three, its clients ask again one by one: the first to come back waits for the other
    # two instead of being read alone while they queue behind it
    reads: list = []
    coalescer = Coalescer(_recording(reads), _cut, hold=30.0)
    jobs = [coalescer.submit("k", [c]) for c in "abc"]
    coalescer.result(jobs[0])
    x = coalescer.submit("k", ["x"])
    waiter = threading.Thread(target=coalescer.result, args=(x,))
    waiter.start()
    time.sleep(0.05)
    assert reads == [["a", "b", "c"]]  # x waits for company
    later = [coalescer.submit("k", [c]) for c in "yz"]
    waiter.join(30)
    assert reads == [["a", "b", "c"], ["x", "y", "z"]] and all(j.done.is_set() for j in later)


def test_a_lone_request_after_a_batch_waits_at_most_hold():
    reads: list = []
    coalescer = Coalescer(_recording(reads), _cut, hold=0.05)
    jobs = [coalescer.submit("k", [c]) for c in "abc"]
    coalescer.result(jobs[0])
    started = time.monotonic()
    assert coalescer.result(coalescer.submit("k", ["x"])) == ["x"]
    assert time.monotonic() - started < 1.0 and reads == [["a", "b", "c"], ["x"]]
