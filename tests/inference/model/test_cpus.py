"""onnxruntime threads sized to the CPUs a container may use: the cgroup quota (v2 and v1), the affinity, and the
workers × concurrent inferences sharing them."""

from __future__ import annotations

import os

import pytest

from curve_vae.inference.model import cpus
from curve_vae.service.settings import Settings


def cgroup(tmp_path, v2: str | None = None, v1: tuple[str, str] | None = None):
    if v2 is not None:
        (tmp_path / "cpu.max").write_text(v2 + "\n")
    if v1 is not None:
        (tmp_path / "cpu").mkdir()
        (tmp_path / "cpu" / "cpu.cfs_quota_us").write_text(v1[0] + "\n")
        (tmp_path / "cpu" / "cpu.cfs_period_us").write_text(v1[1] + "\n")
    return tmp_path


@pytest.mark.parametrize(
    ("v2", "v1", "quota"),
    [
        ("200000 100000", None, 2.0),
        ("150000 100000", None, 1.5),
        ("max 100000", None, None),
        (None, ("50000", "100000"), 0.5),
        (None, ("-1", "100000"), None),
        (None, None, None),  # no cgroup files at all (not Linux, or not mounted)
        ("garbage", None, None),
    ],
)
def test_the_cgroup_quota(tmp_path, v2, v1, quota):
    assert cpus.cgroup_cpus(cgroup(tmp_path, v2, v1)) == quota


def test_available_cpus_are_the_affinity_capped_by_the_quota_rounded_down(tmp_path, monkeypatch):
    def root(name: str, v2: str | None = None):
        (tmp_path / name).mkdir()
        return cgroup(tmp_path / name, v2)

    monkeypatch.setattr(os, "sched_getaffinity", lambda pid: set(range(64)), raising=False)
    assert cpus.available_cpus(root("none")) == 64
    assert cpus.available_cpus(root("a", "250000 100000")) == 2
    assert cpus.available_cpus(root("b", "50000 100000")) == 1  # half a CPU still runs one thread
    monkeypatch.setattr(os, "sched_getaffinity", lambda pid: {0, 1, 2}, raising=False)
    assert cpus.available_cpus(root("c", "800000 100000")) == 3  # pinned to 3 of the 8 the quota allows


@pytest.mark.parametrize(
    ("cpus_", "workers", "concurrency", "threads"),
    [(2, 1, 2, 1), (8, 1, 2, 4), (8, 2, 2, 2), (16, 1, 1, 16), (2, 4, 2, 1), (7, 1, 2, 3)],
)
def test_threads_per_inference_share_the_cpus_out(cpus_, workers, concurrency, threads):
    settings = Settings.model_construct(intra_op_threads=0, workers=workers, inference_concurrency=concurrency)
    assert cpus.threads_per_inference(settings, cpus_) == threads
    assert workers * concurrency * threads <= max(cpus_, workers * concurrency)  # never more threads than CPUs


@pytest.mark.parametrize(
    ("cpus_", "workers", "count", "threads"), [(2, 0, 2, 1), (8, 0, 8, 1), (1, 0, 1, 1), (8, 3, 3, 1), (16, 2, 2, 1)]
)
def test_workers_default_to_one_per_cpu(cpus_, workers, count, threads):
    settings = Settings.model_construct(workers=workers, inference_concurrency=0, intra_op_threads=0)
    assert cpus.worker_count(settings, cpus_) == count
    assert cpus.threads_per_inference(settings, cpus_) == threads


def test_an_explicit_thread_count_wins():
    settings = Settings.model_construct(intra_op_threads=3, workers=4, inference_concurrency=2)
    assert cpus.threads_per_inference(settings, 2) == 3


@pytest.mark.parametrize(
    ("cpus_", "workers", "concurrency", "slots"),
    [(2, 1, 0, 2), (8, 2, 0, 4), (2, 2, 0, 2), (3, 4, 0, 2), (1, 1, 0, 2), (2, 1, 5, 5), (2, 2, 1, 1)],
)
def test_inference_slots_default_to_one_per_cpu_of_a_worker_and_at_least_two(cpus_, workers, concurrency, slots):
    settings = Settings.model_construct(workers=workers, inference_concurrency=concurrency)
    assert cpus.inference_slots(settings, cpus_) == slots


def test_the_service_loads_its_sessions_with_those_threads(make_client, monkeypatch):
    monkeypatch.setattr("curve_vae.inference.model.cpus.available_cpus", lambda root=None: 6)
    client = make_client(share_runtime=False, providers="cpu", workers=1, inference_concurrency=3)
    assert client.get("/ready").status_code == 200
    runtime = client.app.state.runtime
    assert len(runtime.graphs.pool.pairs) == 3  # one session pair per inference at once
    for pair in runtime.graphs.pool.pairs:
        for session in pair:  # read back from onnxruntime, not from our settings
            opts = session.get_session_options()
            assert opts.intra_op_num_threads == 2  # 6 CPUs for 1 worker × 3 inferences at once
            assert opts.inter_op_num_threads == 1
            assert opts.get_session_config_entry("session.intra_op.allow_spinning") == "0"
    assert client.app.state.executor._max_workers == 3
    execution = client.get("/model").json()["execution"]
    assert execution == {
        "sessions": 3,
        "intra_op_threads": 2,
        "inter_op_threads": 1,
        "spinning": False,
        "blas_threads": 2,  # numpy's BLAS as many as onnxruntime
        "inference_threads": 3,
        "gil_switch_ms": 2.0,  # Python's own is 5
        "micro_batch": None,
        "coalesce": {"curves": 32, "readers": 3, "hold_ms": 5.0},  # one batch a CPU, at most one an inference
    }


def test_every_runtime_setting_can_be_overridden(make_client):
    client = make_client(
        share_runtime=False, providers="cpu", intra_op_threads=3, inter_op_threads=2, spinning=True, sessions=1
    )
    execution = client.get("/model").json()["execution"]
    assert execution["sessions"] == 1 and execution["intra_op_threads"] == 3
    assert execution["inter_op_threads"] == 2 and execution["spinning"] is True
    opts = client.app.state.runtime.graphs.encoder.get_session_options()
    assert opts.get_session_config_entry("session.intra_op.allow_spinning") == "1"


def test_each_inference_thread_keeps_its_own_session_pair(make_client, curves):
    """Concurrent requests run on distinct pairs: the executor's threads are spread over the pool."""
    import concurrent.futures as cf
    import threading

    client = make_client(share_runtime=False, providers="cpu", inference_concurrency=2, intra_op_threads=1)
    pool = client.app.state.runtime.graphs.pool
    used: dict[str, int] = {}
    real = pool.pair

    def spy():
        pair = real()
        used[threading.current_thread().name] = id(pair[0])
        return pair

    pool.pair = spy
    body = {"curves": curves(2, 40).tolist(), "pose": "as_is"}
    with cf.ThreadPoolExecutor(4) as callers:
        answers = list(callers.map(lambda _: client.post("/reconstruct", json=body).status_code, range(8)))
    assert answers == [200] * 8
    inference = {name: pair for name, pair in used.items() if name.startswith("inference")}
    assert 1 <= len(inference) <= 2 and len(set(inference.values())) == len(inference)


def test_blas_threads_are_capped_and_read_back():
    import numpy as np  # loads numpy's BLAS
    from threadpoolctl import threadpool_info

    assert cpus.limit_blas_threads(1) == 1 == cpus.blas_threads()
    assert all(lib["num_threads"] == 1 for lib in threadpool_info() if lib["user_api"] == "blas")
    a = np.random.default_rng(0).normal(size=(300, 300))
    assert np.allclose(a @ np.linalg.inv(a), np.eye(300), atol=1e-8)  # still computes
    assert cpus.blas_threads([]) == 0  # none loaded
