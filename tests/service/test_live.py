"""LiveServer (service.live): a command started on a free loopback port, polled on /ready until it answers, stopped
again; its output, exit status, processes and their resources. The servers here are tiny stand-ins (a few lines of
the standard library's http.server, started as the real one is), so each test takes a fraction of a second."""

from __future__ import annotations

import os
import signal
import socket
import sys
import textwrap
import time

import pytest

from curve_vae.service.live import LiveServer, free_port

#: A stand-in for `curve-vae serve`: parses --port, answers GET /ready (200 once READY_AFTER seconds have passed, 503
#: before), prints its arguments, and with CHILD=1 starts a child process that sleeps.
STAND_IN = textwrap.dedent(
    """
    import http.server, os, subprocess, sys, time
    args = sys.argv[1:]
    port = int(args[args.index("--port") + 1])
    start = time.monotonic()
    ready_after = float(os.environ.get("READY_AFTER", "0"))
    if os.environ.get("CHILD") == "1":
        subprocess.Popen([sys.executable, "-c", "import time; time.sleep(60)"])
    if os.environ.get("EXIT"):
        print("cannot start: " + " ".join(args), flush=True)
        sys.exit(int(os.environ["EXIT"]))
    class Handler(http.server.BaseHTTPRequestHandler):
        def do_GET(self):
            ok = self.path == "/ready" and time.monotonic() - start >= ready_after
            self.send_response(200 if ok else 503)
            self.end_headers()
        def log_message(self, *a):
            pass
    print("serving " + " ".join(args), flush=True)
    http.server.HTTPServer(("127.0.0.1", port), Handler).serve_forever()
    """
)
COMMAND = [sys.executable, "-c", STAND_IN]


def test_a_free_port_can_be_bound_on_loopback():
    port = free_port()
    assert 1024 <= port <= 65535
    with socket.socket() as s:
        s.bind(("127.0.0.1", port))


def test_the_server_gets_its_port_and_arguments_and_waits_until_ready():
    with LiveServer("--model-dir", "m", env={"READY_AFTER": "0.3"}, command=COMMAND) as server:
        assert server.url == f"http://127.0.0.1:{server.port}"
        assert server.cmd[-6:] == ["--port", str(server.port), "--log-level", "warning", "--model-dir", "m"]
        assert server.proc.poll() is None
        with socket.create_connection(("127.0.0.1", server.port), timeout=1):
            pass  # __enter__ returned: it listens and /ready answered 200
    assert server.proc.returncode == -signal.SIGTERM  # stopped on leaving the block
    assert server.output() == f"serving --port {server.port} --log-level warning --model-dir m\n"


def test_a_server_that_exits_is_a_runtime_error_with_its_output():
    server = LiveServer("--x", env={"EXIT": "3"}, command=COMMAND, log_level="info")
    with pytest.raises(RuntimeError, match="server exited with 3") as err:
        server.wait_ready(timeout=30)
    assert f"cannot start: --port {server.port} --log-level info --x" in str(err.value)


def test_a_server_slower_than_the_timeout_is_a_timeout_error_and_is_stopped_on_entering():
    server = LiveServer(env={"READY_AFTER": "60"}, command=COMMAND)
    t = time.monotonic()
    with pytest.raises(TimeoutError, match="not ready after 0.5 s"):
        server.wait_ready(timeout=0.5)
    assert time.monotonic() - t < 5
    assert server.proc.poll() is None
    assert server.stop() == -signal.SIGTERM


def test_its_processes_children_included_and_their_resources():
    with LiveServer(env={"CHILD": "1"}, command=COMMAND) as server:
        pids = server.pids()
        assert pids[0] == server.proc.pid and len(pids) == 2
        with open(f"/proc/{pids[1]}/stat") as f:
            assert int(f.read().rsplit(")", 1)[1].split()[1]) == server.proc.pid  # the child's parent: the server
        assert set(server.cpu_seconds()) == set(pids) and all(v >= 0 for v in server.cpu_seconds().values())
        assert 1 < server.rss_mib() < 1000
        child = pids[1]
    os.kill(child, signal.SIGKILL)  # the stand-in leaves its child behind; uvicorn's workers exit with it


def test_stop_kills_a_server_that_ignores_sigterm():
    ignore = [
        sys.executable,
        "-c",
        "import signal, time; signal.signal(signal.SIGTERM, signal.SIG_IGN); time.sleep(60)",
    ]
    server = LiveServer(command=ignore)
    time.sleep(0.3)  # let it install its handler
    assert server.stop(timeout=0.5) == -signal.SIGKILL
    assert server.stop() == -signal.SIGKILL  # stopping again changes nothing
