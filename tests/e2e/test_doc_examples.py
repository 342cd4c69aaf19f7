"""The curl examples of README.md, docs/index.md (Get started) and docs/API.md, pasted as they are against `curve-vae
serve` on the shipped model: each works, and the answer each shows (its `# ...` lines) is what the service answers
(tests/e2e/doc_answers.py)."""

from __future__ import annotations

import json
import re
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[2]


#: The pages whose curl examples must work as pasted.
DOCUMENTED = ("README.md", "docs/index.md", "docs/API.md")


def _curl_blocks() -> list[str]:
    text = "\n".join((ROOT / page).read_text() for page in DOCUMENTED)
    return re.findall(r"```sh\n(.*?)```", text, flags=re.S)


def _check_saved(path: Path) -> None:
    """A file an example saved with `-o`: loadable as what its name says."""
    assert path.is_file(), path
    if path.suffix == ".npy":
        batch = np.load(path, allow_pickle=False)
        assert batch.dtype == np.float32 and batch.ndim == 3 and batch.shape[2] == 2
    elif path.suffix == ".obj":
        lines = path.read_text().splitlines()
        assert any(line.startswith("v ") for line in lines) and any(line.startswith("f ") for line in lines)
    elif path.suffix == ".stl":
        data = path.read_bytes()
        assert len(data) == 84 + 50 * int.from_bytes(data[80:84], "little")


def _documented(block: str) -> list[str]:
    """The answer a block shows: its `# ` lines."""
    return [line[2:] for line in block.splitlines() if line.startswith("# ")]


def _check_headers(body: str, shown: list[str]) -> None:
    """`curl -D -`: the status line and every header the docs show."""
    lines = [line.strip().lower() for line in body.splitlines()]
    for line in shown:
        assert line.strip().lower() in lines or line.startswith("HTTP/") and lines[0].startswith(line.lower()), line


def _shown_scalars(block: str) -> list[tuple[str, str]]:
    """The `"key":value` pairs with a literal number or string that a block's `# {...}` answer line shows."""
    shown = "\n".join(line[2:] for line in block.splitlines() if line.startswith("# {"))
    return re.findall(r'"(\w+)":(-?\d[\d.e-]*|"[^"]*")(?=[,}\]])', shown)


def _first(answer, key: str):
    """The first value of `key` in a JSON answer, depth first."""
    if isinstance(answer, dict):
        if key in answer:
            return answer[key]
        answer = list(answer.values())
    if isinstance(answer, list):
        for item in answer:
            found = _first(item, key)
            if found is not None:
                return found
    return None


SHOWN = [b for b in _curl_blocks() if _shown_scalars(b) and "-o " not in b and "%{http_code}" not in b]


@pytest.mark.skipif(shutil.which("curl") is None, reason="curl is not installed")
@pytest.mark.parametrize("block", _curl_blocks(), ids=lambda b: b.split("http://127.0.0.1:8000")[1].split()[0])
def test_curl_examples_work_as_pasted(shipped_server, block, tmp_path):
    """Each block as pasted, against the shipped model (the model the docs' answers come from); the answer it shows
    matches the service's (tests/e2e/doc_answers.py): keys and shapes always, values to their last printed digit."""
    from tests.e2e.doc_answers import mismatches, parse

    if "| jq" in block and shutil.which("jq") is None:
        pytest.skip("jq is not installed")
    command = block.replace("http://127.0.0.1:8000", shipped_server.url)
    out = subprocess.run(
        ["bash", "-c", f"set -o pipefail\n{command}"], capture_output=True, text=True, timeout=120, cwd=tmp_path
    )
    assert out.returncode == 0, out.stderr
    body, shown = out.stdout.strip(), _documented(block)
    saved = re.findall(r"\s-o (\S+)", block)
    if saved:  # a file, not a JSON body
        for name in saved:
            _check_saved(tmp_path / name)
        if "-D -" in block:
            _check_headers(body, shown)
        return
    assert body
    if "/metrics" in block:
        assert all(line.rsplit(" ", 1)[0] in body for line in shown), body
        return
    if "%{http_code}" in block:
        body, status = body.rsplit("\n", 1)
        assert status == shown[-1] and json.loads(body)["detail"]
    answer = json.loads(body)
    if shown and shown[0].startswith("{"):
        assert not (differ := mismatches(parse(shown[0]), answer)), differ
    elif "%{http_code}" not in block:
        assert "detail" not in answer, answer


@pytest.mark.skipif(shutil.which("curl") is None, reason="curl is not installed")
@pytest.mark.parametrize("block", SHOWN, ids=lambda b: b.split("http://127.0.0.1:8000")[1].split()[0])
def test_readme_answers_show_what_the_shipped_model_answers(shipped_server, block, tmp_path):
    """Every number and string a README example shows in its answer is what the shipped model answers, to the
    digits shown."""
    command = block.replace("http://127.0.0.1:8000", shipped_server.url)
    out = subprocess.run(["bash", "-c", command], capture_output=True, text=True, timeout=60, cwd=tmp_path)
    answer = json.loads(out.stdout)
    for key, shown in _shown_scalars(block):
        actual = _first(answer, key)
        if shown.startswith('"'):
            assert actual == shown.strip('"'), (key, shown, actual)
            continue
        digits = shown.split("e")[0].split(".")[1] if "." in shown.split("e")[0] else ""
        exponent = int(shown.split("e")[1]) if "e" in shown else 0
        unit = 10.0 ** (exponent - len(digits))
        assert isinstance(actual, (int, float)) and abs(actual - float(shown)) <= unit, (key, shown, actual)
