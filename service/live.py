"""A real server on a loopback port, started in a subprocess and stopped again: for tests, benchmarks, the soak and
anyone scripting against a local service.

    with LiveServer("--model-dir", "models") as server:
        httpx.post(f"{server.url}/reconstruct", json={"curves": [...]})

`command` defaults to `python -m curve_vae.service.server` (what `curve-vae serve` runs) in this interpreter; the
wheel's test passes its installed `curve-vae serve` instead. Standard library only.
"""

from __future__ import annotations

import os
import socket
import subprocess
import sys
import time
import urllib.error
import urllib.request
from collections.abc import Sequence
from pathlib import Path
from types import SimpleNamespace
from typing import Self


def free_port() -> int:
    """A loopback port nothing listens on (now)."""
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def listening_sockets(port: int) -> int | None:
    """TCP sockets listening on `port` on this machine, any address (Linux's /proc/net/tcp and tcp6); None where
    there are no such tables to read."""
    tables = [Path(t) for t in ("/proc/net/tcp", "/proc/net/tcp6") if Path(t).is_file()]
    if not tables:
        return None
    count = 0
    for table in tables:
        for row in table.read_text().splitlines()[1:]:
            fields = row.split()
            count += fields[3] == "0A" and int(fields[1].rsplit(":", 1)[1], 16) == port  # 0A: LISTEN
    return count


#: How long `wait_ready` waits by default: a start with an empty numba cache compiles the reading's kernels in its
#: warm-up request before /ready answers (18.8 s for two workers on this project's 2 cores, alone: longer beside
#: other work).
READY_TIMEOUT = 180.0


def _workers(args: list[str], env: dict[str, str]) -> int:
    """How many workers a server started with `args` in `env` runs: its --workers, or CURVE_VAE_WORKERS; 0 (the
    default) is one a CPU, as the server counts them (inference.model.cpus)."""
    from curve_vae.inference.model.cpus import worker_count

    count = env.get("CURVE_VAE_WORKERS", "0")
    if "--workers" in args[:-1]:
        count = args[args.index("--workers") + 1]
    return worker_count(SimpleNamespace(workers=int(count) if count.isdigit() else 0))


class LiveServer:
    """The service in a subprocess on a free loopback port; `wait_ready` polls GET /ready until it answers 200."""

    def __init__(
        self,
        *args: str,
        env: dict[str, str] | None = None,
        command: Sequence[str] | None = None,
        cwd: str | Path | None = None,
        capture: bool = True,
        log_level: str = "warning",
    ) -> None:
        self.port = free_port()
        self.url = f"http://127.0.0.1:{self.port}"
        base = list(command) if command is not None else [sys.executable, "-m", "curve_vae.service.server"]
        self.cmd = [*base, "--port", str(self.port), "--log-level", log_level, *args]
        # the service's workers; another command (a stand-in) is one process unless it says --workers
        given = command is None or "--workers" in args
        self.workers = _workers(list(args), {**os.environ, **(env or {})}) if given else 1
        out = subprocess.PIPE if capture else None
        self._printed: str | None = None
        self.proc = subprocess.Popen(
            self.cmd,
            cwd=cwd,
            env={**os.environ, **(env or {})},
            stdout=out,
            stderr=subprocess.STDOUT if capture else None,
            text=True,
        )

    def __enter__(self) -> Self:
        try:
            self.wait_ready()
        except BaseException:
            self.stop()
            raise
        return self

    def __exit__(self, *exc: object) -> None:
        self.stop()

    def output(self) -> str:
        """What the server printed (a stopped server's, when captured)."""
        if self._printed is None and self.proc.stdout is not None and self.proc.poll() is not None:
            self._collect()
        return self._printed or ""

    def _collect(self) -> None:
        """Read what an exited server printed and close the pipe (an open one is a leaked file); a pipe that a
        leftover child still holds is left to it."""
        try:
            self._printed = self.proc.communicate(timeout=5)[0] or ""
        except subprocess.TimeoutExpired:
            self._printed = ""

    def wait_ready(self, timeout: float = READY_TIMEOUT, *, workers: int | None = None) -> None:
        """Poll /ready until 200. Each of `workers` (default: as many as the server starts) warms up on its own, and
        a new connection reaches any one of them: with several, 4 × `workers` new connections in a row must each
        answer 200, and /metrics must say every worker is ready (`_every_worker_ready`). RuntimeError (with the
        server's output) if it exits, TimeoutError if it is slow."""
        workers = self.workers if workers is None else workers
        deadline = time.monotonic() + timeout
        in_a_row = 0
        while time.monotonic() < deadline:
            if self.proc.poll() is not None:
                raise RuntimeError(f"server exited with {self.proc.returncode}: {' '.join(self.cmd)}\n{self.output()}")
            try:
                with urllib.request.urlopen(f"{self.url}/ready", timeout=1) as r:
                    ready = r.status == 200
            except OSError:
                ready = False
            in_a_row = in_a_row + 1 if ready else 0
            if in_a_row >= (1 if workers <= 1 else 4 * workers):
                if workers <= 1 or self._every_worker_ready():
                    return
                ready = False
            if not ready:
                time.sleep(0.1)
        raise TimeoutError(f"{self.url} not ready after {timeout:g} s")

    def _every_worker_ready(self) -> bool:
        """What /metrics says of the workers (`curve_vae_ready`: the least over the live workers, service.metrics):
        the workers share one socket, and new connections in a row may all reach the same one. True where the
        server keeps no metrics."""
        try:
            with urllib.request.urlopen(f"{self.url}/metrics", timeout=5) as r:
                text = r.read().decode()
        except urllib.error.HTTPError as e:
            return e.code in (401, 403, 404)  # metrics off, or behind a key: the connections in a row are all there is
        except OSError:
            return False
        values = [line.split()[-1] for line in text.splitlines() if line.startswith("curve_vae_ready ")]
        return bool(values) and float(values[0]) == 1.0

    def pids(self) -> list[int]:
        """The server process and all its descendants (uvicorn's workers), from /proc."""
        out, todo = [], [self.proc.pid]
        while todo:
            pid = todo.pop()
            out.append(pid)
            try:
                todo += [int(c) for c in Path(f"/proc/{pid}/task/{pid}/children").read_text().split()]
            except OSError:
                pass
        return out

    def cpu_seconds(self) -> dict[int, float]:
        """User + system CPU seconds of each server process so far."""
        tick = os.sysconf("SC_CLK_TCK")
        out = {}
        for pid in self.pids():
            try:
                fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
            except OSError:
                continue
            out[pid] = (int(fields[11]) + int(fields[12])) / tick  # utime, stime
        return out

    def rss_mib(self) -> float:
        """Resident memory of the server's processes, MiB."""
        total = 0
        for pid in self.pids():
            try:
                for line in Path(f"/proc/{pid}/status").read_text().splitlines():
                    if line.startswith("VmRSS:"):
                        total += int(line.split()[1])
            except OSError:
                continue
        return total / 1024

    def stop(self, timeout: float = 15.0) -> int:
        """Terminate (then kill) the server; its exit code."""
        if self.proc.poll() is None:
            self.proc.terminate()
            try:
                self.proc.wait(timeout=timeout)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait()
        if self._printed is None and self.proc.stdout is not None:
            self._collect()
        return self.proc.returncode
