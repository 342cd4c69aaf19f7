"""curve_vae.progress: bars drawn on a terminal, never into a pipe or a log, off with --no-progress; a bar counts
the rows that pass it."""

from __future__ import annotations

import fcntl
import io
import json
import os
import pty
import struct
import subprocess
import sys
import termios
from pathlib import Path

import pytest

from curve_vae.progress import bar, counted, shown
from tests.helpers import ROOT

SEEDS = [[[0, 0], [1, 2], [2.5, 3.2], [4, 3.5], [5.5, 3], [7, 1.5], [8, 0]], [[0, 0], [1, 1], [2, 3], [3, 2], [4, 4]]]


def _augment(tmp_path: Path, *extra: str, terminal: bool) -> str:
    """Run `curve-vae augment` with stderr on a 100-column pseudo-terminal or a pipe; what it wrote to stderr."""
    seeds = tmp_path / "seeds.json"
    seeds.write_text(json.dumps(SEEDS))
    cmd = [sys.executable, "-m", "curve_vae.cli", "augment", str(seeds), "--count", "400", "--seed", "1"]
    cmd += ["-o", str(tmp_path / "out.npy"), "--force", *extra]
    if not terminal:
        return subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True, timeout=120, check=True).stderr
    main, other = pty.openpty()
    fcntl.ioctl(other, termios.TIOCSWINSZ, struct.pack("HHHH", 30, 100, 0, 0))
    proc = subprocess.Popen(cmd, cwd=ROOT, stdout=subprocess.DEVNULL, stderr=other, stdin=subprocess.DEVNULL)
    os.close(other)
    out = b""
    while True:
        try:
            data = os.read(main, 4096)
        except OSError:  # the terminal closed with the process
            break
        if not data:
            break
        out += data
    assert proc.wait(timeout=120) == 0
    os.close(main)
    return out.decode(errors="replace")


@pytest.mark.skipif(not (ROOT / "models" / "manifest.json").is_file(), reason="no shipped model")
def test_augment_shows_a_bar_on_a_terminal_only(tmp_path):
    shown = _augment(tmp_path, terminal=True)
    assert "augment:" in shown and "/400" in shown, shown[-500:]
    assert "augment:" not in _augment(tmp_path, terminal=False)
    quiet = _augment(tmp_path, "--no-progress", terminal=True)
    assert "augment:" not in quiet and "400 new curves" in quiet


class _Stream:
    def __init__(self, tty: bool) -> None:
        self.tty = tty

    def isatty(self) -> bool:
        return self.tty

    def write(self, text: str) -> int:
        return len(text)

    def flush(self) -> None:
        pass


@pytest.mark.parametrize(
    ("tty", "no_progress", "want"),
    [
        pytest.param(True, False, True, id="terminal"),
        pytest.param(True, True, False, id="terminal-no-progress"),
        pytest.param(False, False, False, id="pipe"),
        pytest.param(False, True, False, id="pipe-no-progress"),
    ],
)
def test_bars_are_shown_on_a_terminal_unless_asked_off(monkeypatch, tty, no_progress, want):
    monkeypatch.setattr(sys, "stderr", _Stream(tty))
    assert shown(no_progress) is want


def test_a_bar_counts_the_rows_of_each_chunk_as_it_passes():
    chunks = [[1] * 3, [2] * 5, [], [3] * 2]
    with bar(10, "augment", enabled=True, file=io.StringIO()) as progress:
        seen = [(chunk, progress.n) for chunk in counted(chunks, progress)]  # counted before it is handed on
    assert seen == list(zip(chunks, [3, 8, 8, 10])) and progress.n == progress.total == 10
    assert progress.desc == "augment" and progress.unit == "curve"


def test_a_bar_that_is_off_draws_nothing():
    out = io.StringIO()
    with bar(10, "augment", enabled=False, file=out) as progress:
        list(counted([[0] * 4], progress))
    assert progress.disable and out.getvalue() == ""
