"""Progress bars: drawn on a terminal, never into a pipe or a log, off with --no-progress."""

from __future__ import annotations

import fcntl
import json
import os
import pty
import struct
import subprocess
import sys
import termios
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
SEEDS = [[[0, 0], [1, 2], [2.5, 3.2], [4, 3.5], [5.5, 3], [7, 1.5], [8, 0]], [[0, 0], [1, 1], [2, 3], [3, 2], [4, 4]]]


def _augment(tmp_path: Path, *extra: str, terminal: bool) -> str:
    """Run `curve-vae augment` with stderr on a 100-column pseudo-terminal or a pipe; what it wrote to stderr."""
    seeds = tmp_path / "seeds.json"
    seeds.write_text(json.dumps(SEEDS))
    cmd = [sys.executable, "-m", "curve_vae.cli", "augment", str(seeds), "--count", "2000", "--seed", "1"]
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
    assert "augment:" in shown and "/2000" in shown, shown[-500:]
    assert "augment:" not in _augment(tmp_path, terminal=False)
    assert "augment:" not in _augment(tmp_path, "--no-progress", terminal=True)
    assert "2000 new curves" in _augment(tmp_path, "--no-progress", terminal=True)
