"""`curve-vae serve` (service.server): a real uvicorn process on a loopback port, called with httpx; its flags, defaults
and configuration errors, workers, and shutdown on SIGTERM (requests in flight finish, exit 0)."""

from __future__ import annotations

import concurrent.futures as cf
import json
import shutil
import signal
import subprocess
import tempfile
import threading
import time
from pathlib import Path

import httpx
import numpy as np
import onnxruntime as ort
import pytest

from curve_vae.service.live import listening_sockets

ROOT = Path(__file__).resolve().parents[2]
C = [[0, 0], [1, 2], [2.5, 3.2], [4, 3.5], [5.5, 3], [7, 1.5], [8, 0]]


def test_endpoints_over_a_socket(live_server, curves):
    with httpx.Client(base_url=live_server.url, timeout=30) as http:
        assert http.get("/health").json() == {"status": "ok"}
        assert http.get("/model").json()["providers"] == ["CPUExecutionProvider"]
        before = _counts(http.get("/metrics").text)  # the server is shared: other tests' requests are counted too
        c = curves(2, 90) * 0.2 - 3
        rec = http.post("/reconstruct", json={"curves": c.tolist()})
        assert rec.status_code == 200 and np.shape(rec.json()["curves"]) == (2, 90, 2)
        inter = http.post("/interpolate", json={"curves": c.tolist(), "steps": 4, "n_points": 30})
        assert np.shape(inter.json()["curves"]) == (4, 30, 2)
        bad = http.post(
            "/encode",
            content=b'{"curves": [[[0,0],[1,NaN],[2,3],[3,1]]]}',
            headers={"Content-Type": "application/json"},
        )
        assert bad.status_code == 422 and bad.json()["detail"] == "curves[0][1][1]: not a finite number"
        big = http.post("/encode", json={"curves": [np.linspace(0, 1, 8000).reshape(-1, 2).tolist()] * 10})
        assert big.status_code == 413  # the server was started with --max-body-bytes 200000
        after = _counts(http.get("/metrics").text)
        for route, status in (("/encode", "413"), ("/reconstruct", "200"), ("/interpolate", "200"), ("/encode", "422")):
            key = f'method="POST",route="{route}",status="{status}"'
            assert after.get(key, 0) - before.get(key, 0) == 1, key


def test_numpys_blas_runs_one_inferences_threads(live_server):
    """The reading's small matrix products (ranker, spacing guesser, fit) run on numpy's BLAS, which starts a thread
    per core of its own: the server holds it to the threads of one inference, read back from the live process."""
    execution = httpx.get(f"{live_server.url}/model", timeout=30).json()["execution"]
    assert execution["blas_threads"] == execution["intra_op_threads"] >= 1


def test_the_worker_hands_the_gil_round_sooner_than_pythons_own_5_ms(live_server):
    """sys.getswitchinterval() of the live worker: the setting's 2 ms, so the event loop waits less behind the
    inference threads."""
    execution = httpx.get(f"{live_server.url}/model", timeout=30).json()["execution"]
    assert execution["gil_switch_ms"] == 2.0


def _counts(metrics: str) -> dict[str, float]:
    """curve_vae_http_requests_total by its labels, from a Prometheus text page."""
    out = {}
    for line in metrics.splitlines():
        if line.startswith("curve_vae_http_requests_total{"):
            labels, value = line[len("curve_vae_http_requests_total{") :].rsplit("} ", 1)
            out[labels] = float(value)
    return out


def test_concurrent_requests(live_server, curves):
    """Inference runs off the event loop: /health answers while requests are in flight."""
    import concurrent.futures as cf

    body = {"curves": curves(16, 161).tolist()}  # under the server's 200 kB body limit
    with httpx.Client(base_url=live_server.url, timeout=60) as http, cf.ThreadPoolExecutor(4) as pool:
        futures = [pool.submit(http.post, "/reconstruct", json=body) for _ in range(3)]
        assert http.get("/health", timeout=5).status_code == 200
        assert all(f.result().status_code == 200 for f in futures)


def test_two_workers(server_factory, model_dir):
    """Workers are separate processes that rebuild the settings from the environment; at the info level the startup
    log says once what is served and where the page, the API docs and the metrics are, not once per worker."""
    args = ("--model-dir", str(model_dir), "--providers", "cpu", "--workers", "2", "--max-curves", "3")
    server = server_factory(*args, "--log-level", "info")
    server.wait_ready(workers=2)
    r = httpx.post(f"{server.url}/encode", json={"curves": [C] * 4}, timeout=30)
    assert r.status_code == 422 and "at most 3 curves" in r.json()["detail"]
    assert server.stop() == 0
    log = server.output()
    page = f"the page: {server.url}/ · the API docs: {server.url}/docs · metrics: {server.url}/metrics"
    assert log.count(page) == 1, log
    for line in ("serving curve-vae", "onnxruntime: ", "Application startup complete"):
        assert log.count(line) == 1, (line, log)


def test_one_process_says_where_the_page_is(server_factory, model_dir):
    args = ("--model-dir", str(model_dir), "--providers", "cpu", "--workers", "1")
    server = server_factory(*args, "--log-level", "info")
    server.wait_ready()
    assert server.stop() == 0
    assert f"the page: {server.url}/ · the API docs: {server.url}/docs" in server.output()


def test_two_workers_share_the_connections_out(server_factory, model_dir, curves):
    """The workers accept from uvicorn's one shared socket: keep-alive clients that open their connections at once
    land on both workers, not all on the first to accept."""
    server = server_factory("--model-dir", str(model_dir), "--providers", "cpu", "--workers", "2")
    server.wait_ready(workers=2)
    before = server.cpu_seconds()
    body = {"curves": curves(32, 161).tolist()}
    start = threading.Barrier(32)

    def client(_: int) -> list[int]:
        with httpx.Client(base_url=server.url, timeout=60) as http:
            start.wait()  # 32 connections opened together, then kept alive
            return [http.post("/reconstruct", json=body).status_code for _ in range(3)]

    with cf.ThreadPoolExecutor(32) as pool:
        assert all(code == 200 for codes in pool.map(client, range(32)) for code in codes)
    used = sorted(t - before.get(pid, 0.0) for pid, t in server.cpu_seconds().items())
    # the two workers are the two busiest processes (the supervisor and multiprocessing's tracker are idle)
    assert used[-2] >= 0.15 * (used[-1] + used[-2]), used
    assert server.stop() == 0


def test_workers_stop_when_their_supervisor_is_killed(server_factory, model_dir):
    """SIGKILL to the supervisor: it cannot stop its workers, so each stops itself within seconds (the port is free
    again for a restarted server), rather than serve on as orphans."""
    server = server_factory("--model-dir", str(model_dir), "--providers", "cpu", "--workers", "2")
    server.wait_ready(workers=2)
    workers = [pid for pid in server.pids() if pid != server.proc.pid]
    assert len(workers) >= 2  # the two workers (and multiprocessing's resource tracker)
    server.proc.kill()
    server.proc.wait(timeout=10)
    deadline = time.monotonic() + 30
    while time.monotonic() < deadline and not all(_gone(pid) for pid in workers):
        time.sleep(0.2)
    assert all(_gone(pid) for pid in workers), "workers outlived their supervisor"
    assert listening_sockets(server.port) in (0, None)


def _gone(pid: int) -> bool:
    """Whether a process has exited (a zombie not yet reaped by whoever adopted it counts as exited)."""
    try:
        return Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0] == "Z"
    except OSError:
        return True


def test_workers_refuse_a_port_another_server_listens_on(server_factory, model_dir):
    """A second server on a port in use exits 3 (uvicorn's code for a failed start), naming the address."""
    first = server_factory("--model-dir", str(model_dir), "--providers", "cpu", "--workers", "2")
    first.wait_ready(workers=2)
    second = _serve("--model-dir", str(model_dir), "--providers", "cpu", "--workers", "2", "--port", str(first.port))
    assert second.returncode == 3
    assert f"cannot listen on 127.0.0.1:{first.port}" in second.stdout + second.stderr
    assert "in use" in second.stdout + second.stderr
    assert httpx.get(f"{first.url}/ready", timeout=10).status_code == 200  # the first server is untouched


def test_with_workers_a_scrape_of_any_worker_counts_them_all(server_factory, model_dir):
    """prometheus-client's multiprocess mode: requests answered by either worker show in /metrics wherever the
    scrape lands, the gauges summed over the live workers; the shared directory goes when the server stops."""
    server = server_factory("--model-dir", str(model_dir), "--providers", "cpu", "--workers", "2")
    server.wait_ready(workers=2)
    start = threading.Barrier(24)

    def client(_: int) -> int:
        with httpx.Client(base_url=server.url, timeout=60) as http:
            start.wait()  # 24 connections at once: both workers answer some (see the test above)
            return http.post("/encode", json={"curves": [C]}).status_code

    with cf.ThreadPoolExecutor(24) as pool:
        assert list(pool.map(client, range(24))) == [200] * 24
    key = 'method="POST",route="/encode",status="200"'
    for _ in range(4):  # fresh connections: scrapes that reach either worker read the same totals
        page = httpx.get(f"{server.url}/metrics", timeout=30).text
        assert _counts(page)[key] == 24
        rows = _gauge(page, 'curve_vae_graph_rows{graph="encoder"}')
        assert rows >= 24  # both workers' rows (each also ran its warm-up), summed
        assert _gauge(page, "curve_vae_ready") == 1.0
    pids = server.pids()
    mine = [str(d) for d in Path(tempfile.gettempdir()).glob("curve-vae-metrics-*") if _used_by(str(d), pids)]
    assert server.stop() == 0
    assert mine and not any(Path(d).exists() for d in mine)  # removed at exit


def _gauge(metrics: str, name: str) -> float:
    line = next(ln for ln in metrics.splitlines() if ln.startswith(name + " "))
    return float(line.rsplit(" ", 1)[1])


def _used_by(directory: str, pids: list[int]) -> bool:
    """Whether one of `pids` has a file of `directory` open or mapped (prometheus-client's .db files are mmapped)."""
    for pid in pids:
        try:
            if directory in Path(f"/proc/{pid}/maps").read_text():
                return True
        except OSError:
            continue
    return False


def test_sigterm_shuts_down_cleanly(server_factory, model_dir):
    server = server_factory("--model-dir", str(model_dir), "--providers", "cpu", "--log-level", "info")
    server.wait_ready()
    server.proc.terminate()
    # uvicorn shuts down gracefully, then re-raises the signal so the exit status tells it was terminated
    assert server.proc.wait(timeout=20) in (0, -signal.SIGTERM)
    log = server.proc.stdout.read()  # type: ignore[union-attr]
    assert "Application shutdown complete" in log and "Traceback" not in log


@pytest.mark.parametrize("workers", ["1", "2"])
def test_a_model_that_fails_at_startup_stops_the_server(server_factory, model_dir, tmp_path, workers):
    broken = tmp_path / "model"
    shutil.copytree(model_dir, broken)
    manifest = json.loads((broken / "manifest.json").read_text())
    manifest["latent_dim"] = 16  # checksums still match; the graphs do not
    (broken / "manifest.json").write_text(json.dumps(manifest))
    server = server_factory("--model-dir", str(broken), "--providers", "cpu", "--workers", workers)
    assert server.proc.wait(timeout=60) == 3
    assert "graphs do not match the manifest" in server.proc.stdout.read()  # type: ignore[union-attr]


# ----------------------------------------------------------------------------- CLI configuration errors


def _serve(*args: str) -> subprocess.CompletedProcess[str]:
    import sys

    cmd = [sys.executable, "-m", "curve_vae.service.server", *args]
    return subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True, timeout=60)


@pytest.mark.skipif("CUDAExecutionProvider" in ort.get_available_providers(), reason="CUDA is available here")
def test_cuda_where_unavailable_is_a_clear_startup_error(model_dir):
    out = _serve("--model-dir", str(model_dir), "--providers", "cuda")
    assert out.returncode == 2
    assert "providers=cuda" in out.stderr and "onnxruntime-gpu" in out.stderr


def test_configuration_errors(tmp_path, model_dir, capsys):
    import argparse

    from curve_vae.service.server import configure_parser, run

    parser = argparse.ArgumentParser()
    configure_parser(parser)
    assert run(parser.parse_args(["--model-dir", str(tmp_path)])) == 2
    assert "manifest.json is missing" in capsys.readouterr().err
    assert run(parser.parse_args(["--model-dir", str(model_dir), "--max-points", "2"])) == 2
    assert "max_points" in capsys.readouterr().err
    assert run(parser.parse_args(["--model-dir", str(model_dir), "--gil-switch-ms", "0"])) == 2
    assert "gil_switch_ms" in capsys.readouterr().err


def test_help_names_defaults_and_variables():
    out = _serve("--help")
    assert out.returncode == 0
    for text in ("--providers", "CURVE_VAE_PROVIDERS", "default: auto", "--model-dir", "CURVE_VAE_MAX_BODY_BYTES"):
        assert text in out.stdout


def test_help_puts_what_everyone_sets_first_and_tuning_under_its_own_heading():
    """Every Settings field has its flag once, in a group: the options people set first, then limits, then tuning."""
    from curve_vae.service.server import GROUPS, flagged
    from curve_vae.service.settings import Settings

    text = _serve("--help").stdout
    first, limits, tuning = (text.index(f"\n{title}:") for title in GROUPS.values())
    assert first < limits < tuning
    for flag in ("--host", "--port", "--model-dir", "--workers"):
        assert first < text.index(f"  {flag}") < limits, flag
    for flag in ("--spinning", "--micro-batch", "--inter-op-threads", "--sessions", "--coalesce-curves"):
        assert text.index(f"  {flag}") > tuning, flag
    assert text.splitlines()[0].startswith("usage: ") and len(text.split("\n\n")[0].splitlines()) == 1
    flags = [name for names in flagged().values() for name in names]
    assert sorted(flags) == sorted(set(flags))
    assert set(Settings.model_fields) - set(flags) == {"api_keys", "metrics"}  # set by environment only
    for name in flags:  # each field's own description is its help
        assert " ".join(Settings.model_fields[name].description.split()[:4]) in " ".join(text.split()), name


def test_flags_override_the_environment(monkeypatch):
    import argparse

    from curve_vae.service.server import configure_parser, settings_from_args

    monkeypatch.setenv("CURVE_VAE_PORT", "9001")
    monkeypatch.setenv("CURVE_VAE_WORKERS", "3")
    parser = argparse.ArgumentParser()
    configure_parser(parser)
    settings = settings_from_args(
        parser.parse_args(["--port", "9002", "--cors-origins", "https://a.example,https://b"])
    )
    assert (settings.port, settings.workers, settings.cors_origins) == (9002, 3, ["https://a.example", "https://b"])


CURVE = [[0, 0], [1, 2], [2.5, 3.2], [4, 3.5], [5.5, 3], [7, 1.5], [8, 0]]


def test_sigterm_lets_requests_in_flight_finish_then_exits_0(server_factory, model_dir):
    server = server_factory("--model-dir", str(model_dir), "--providers", "cpu")
    server.wait_ready()
    body = {"curves": [CURVE, CURVE[::-1]], "count": 600, "format": "npy", "seed": 1, "n_points": 161}
    expected = 128 + 600 * 161 * 2 * 4
    with httpx.Client(timeout=120) as http, cf.ThreadPoolExecutor(1) as pool:
        started = threading.Event()

        def download() -> int:
            with http.stream("POST", server.url + "/augment", json=body) as r:
                size = 0
                for chunk in r.iter_bytes():
                    started.set()
                    size += len(chunk)
                return size

        future = pool.submit(download)
        assert started.wait(30)
        server.proc.send_signal(signal.SIGTERM)  # mid-stream
        assert future.result() == expected  # the whole file arrived
    assert server.proc.wait(timeout=60) == 0
    assert "Traceback" not in server.proc.stdout.read()  # type: ignore[union-attr]
