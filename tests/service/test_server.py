"""A real uvicorn process on a loopback port (what `curve-vae serve` starts), called with httpx and curl."""

from __future__ import annotations

import json
import re
import shutil
import signal
import subprocess
from pathlib import Path

import httpx
import numpy as np
import onnxruntime as ort
import pytest

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


#: The pages whose curl examples must work as pasted.
DOCUMENTED = ("README.md", "docs/API.md")


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


@pytest.mark.skipif(shutil.which("curl") is None, reason="curl is not installed")
@pytest.mark.parametrize("block", _curl_blocks(), ids=lambda b: b.split("http://127.0.0.1:8000")[1].split()[0])
def test_curl_examples_work_as_pasted(shipped_server, block, tmp_path):
    """Each block as pasted, against the shipped model (the model the docs' answers come from); the answer it shows
    matches the service's (tests/service/doc_answers.py): keys and shapes always, values to their last printed digit."""
    from tests.service.doc_answers import mismatches, parse

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


def test_two_workers(server_factory, model_dir):
    """Workers are separate processes that rebuild the settings from the environment."""
    server = server_factory("--model-dir", str(model_dir), "--providers", "cpu", "--workers", "2", "--max-curves", "3")
    server.wait_ready(timeout=60)
    r = httpx.post(f"{server.url}/encode", json={"curves": [C] * 4}, timeout=30)
    assert r.status_code == 422 and "at most 3 curves" in r.json()["detail"]
    assert server.stop() == 0


def test_sigterm_shuts_down_cleanly(server_factory, model_dir):
    server = server_factory("--model-dir", str(model_dir), "--providers", "cpu", "--log-level", "info")
    server.wait_ready()
    server.proc.terminate()
    # uvicorn shuts down gracefully, then re-raises the signal so the exit status tells it was terminated
    assert server.proc.wait(timeout=20) in (0, -signal.SIGTERM)
    log = server.proc.stdout.read()  # type: ignore[union-attr]
    assert "Application shutdown complete" in log and "Traceback" not in log


def test_a_model_that_fails_at_startup_stops_the_server(server_factory, model_dir, tmp_path):
    broken = tmp_path / "model"
    shutil.copytree(model_dir, broken)
    manifest = json.loads((broken / "manifest.json").read_text())
    manifest["latent_dim"] = 16  # checksums still match; the graphs do not
    (broken / "manifest.json").write_text(json.dumps(manifest))
    server = server_factory("--model-dir", str(broken), "--providers", "cpu")
    assert server.proc.wait(timeout=60) == 3
    assert "graphs do not match the manifest" in server.proc.stdout.read()  # type: ignore[union-attr]


# ----------------------------------------------------------------------------- CLI configuration errors


def _serve(*args: str) -> subprocess.CompletedProcess[str]:
    import sys

    cmd = [sys.executable, "-m", "curve_vae.service.cli", *args]
    return subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True, timeout=60)


@pytest.mark.skipif("CUDAExecutionProvider" in ort.get_available_providers(), reason="CUDA is available here")
def test_cuda_where_unavailable_is_a_clear_startup_error(model_dir):
    out = _serve("--model-dir", str(model_dir), "--providers", "cuda")
    assert out.returncode == 2
    assert "providers=cuda" in out.stderr and "onnxruntime-gpu" in out.stderr


def test_configuration_errors(tmp_path, model_dir, capsys):
    import argparse

    from curve_vae.service.cli import configure_parser, run

    parser = argparse.ArgumentParser()
    configure_parser(parser)
    assert run(parser.parse_args(["--model-dir", str(tmp_path)])) == 2
    assert "manifest.json is missing" in capsys.readouterr().err
    assert run(parser.parse_args(["--model-dir", str(model_dir), "--max-points", "2"])) == 2
    assert "max_points" in capsys.readouterr().err


def test_help_names_defaults_and_variables():
    out = _serve("--help")
    assert out.returncode == 0
    for text in ("--providers", "CURVE_VAE_PROVIDERS", "default: auto", "--model-dir", "CURVE_VAE_MAX_BODY_BYTES"):
        assert text in out.stdout


def test_flags_override_the_environment(monkeypatch):
    import argparse

    from curve_vae.service.cli import configure_parser, settings_from_args

    monkeypatch.setenv("CURVE_VAE_PORT", "9001")
    monkeypatch.setenv("CURVE_VAE_WORKERS", "3")
    parser = argparse.ArgumentParser()
    configure_parser(parser)
    settings = settings_from_args(
        parser.parse_args(["--port", "9002", "--cors-origins", "https://a.example,https://b"])
    )
    assert (settings.port, settings.workers, settings.cors_origins) == (9002, 3, ["https://a.example", "https://b"])


def test_an_oversized_body_from_the_standard_library_client_gets_the_413(live_server):
    """urllib sends the whole body before it reads the answer: the server reads the rest and drops it, then answers."""
    import urllib.error
    import urllib.request

    body = json.dumps({"curves": [np.linspace(0, 1, 8000).reshape(-1, 2).tolist()] * 40}).encode()  # ~3 MB
    assert len(body) > 10 * 200_000  # far over the server's --max-body-bytes
    req = urllib.request.Request(
        f"{live_server.url}/encode", data=body, headers={"Content-Type": "application/json"}, method="POST"
    )
    with pytest.raises(urllib.error.HTTPError) as err:
        urllib.request.urlopen(req, timeout=30)
    assert err.value.code == 413
    assert "exceeds the limit of 200000 bytes" in json.loads(err.value.read())["detail"]
    assert httpx.get(f"{live_server.url}/health").status_code == 200


def test_an_oversized_body_after_expect_100_continue_is_refused_unread(live_server):
    """curl asks before sending a large body: the 413 comes at once and the body is never sent."""
    if shutil.which("curl") is None:
        pytest.skip("curl is not installed")
    out = subprocess.run(
        [
            "curl",
            "-s",
            "-o",
            "/dev/null",
            "-w",
            "%{http_code} %{size_upload}",
            "-H",
            "Content-Type: application/json",
            "-H",
            "Expect: 100-continue",
            "--data-binary",
            "@-",
            f"{live_server.url}/encode",
        ],
        input=b"[" + b"0," * 1_000_000 + b"0]",
        capture_output=True,
        timeout=30,
    )
    code, uploaded = out.stdout.decode().split()
    assert code == "413" and float(uploaded) < 2_000_000


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
