"""The wheel serves: built from this tree, installed (not editable) in a fresh virtualenv, run from elsewhere.

The fresh environment gets the wheel alone; its dependencies are the test environment's, reached through a
.pth path entry (which does not run the editable install's own finder, so this checkout cannot stand in for
the wheel), with torch hidden as a user's install lacks it. The server is started from a folder outside the
checkout and must find the shipped model inside the package.
"""

import json
import os
import shutil
import subprocess
import sys
import sysconfig
import urllib.request
import zipfile
from pathlib import Path

import pytest

from curve_vae.service.live import LiveServer

ROOT = Path(__file__).resolve().parents[1]
pytestmark = [pytest.mark.slow, pytest.mark.integration]


HIDE_TORCH = """import sys


class HideTorch:
    def find_spec(self, name, path=None, target=None):
        if name == "torch" or name.startswith("torch."):
            raise ModuleNotFoundError(f"No module named {name!r}", name=name)
        return None


sys.meta_path.insert(0, HideTorch())
"""


#: Where the wheel's folders come from in the tree (pyproject.toml's package-dir); the rest is curve_vae/ itself.
MAPPED = ("geometry", "inference", "service", "training", "models")


def tree_files() -> list[str]:
    """The project's files: tracked, or new and not ignored (what the next commit would hold)."""
    listed = subprocess.run(
        ["git", "ls-files", "--cached", "--others", "--exclude-standard", "-z"],
        cwd=ROOT,
        check=True,
        capture_output=True,
    )
    return [name for name in listed.stdout.decode().split("\0") if name and (ROOT / name).is_file()]


@pytest.fixture(scope="module")
def wheel(tmp_path_factory) -> Path:
    """The wheel built from a copy of the tree's files: setuptools builds in the source folder, and its build/ keeps
    every file it ever copied there, so a wheel built in a checkout can hold modules the tree no longer has."""
    out, src = tmp_path_factory.mktemp("wheel"), tmp_path_factory.mktemp("src")
    for name in tree_files():
        (src / name).parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(ROOT / name, src / name)
    subprocess.run(
        [sys.executable, "-m", "pip", "wheel", "--no-deps", "--no-build-isolation", "-q", "-w", str(out), str(src)],
        check=True,
        cwd=src,
        env={**os.environ, "PIP_NO_INPUT": "1"},
        capture_output=True,
    )
    (whl,) = out.glob("curve_vae-*.whl")
    return whl


@pytest.fixture(scope="module")
def venv(wheel, tmp_path_factory) -> Path:
    env = tmp_path_factory.mktemp("venv")
    subprocess.run([sys.executable, "-m", "venv", "--without-pip", str(env)], check=True)
    subprocess.run(
        [
            sys.executable,
            "-m",
            "pip",
            "--python",
            str(env / "bin" / "python"),
            "install",
            "-q",
            "--no-deps",
            str(wheel),
        ],
        check=True,
        capture_output=True,
    )
    site = Path(
        subprocess.run(
            [str(env / "bin" / "python"), "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"],
            check=True,
            capture_output=True,
            text=True,
        ).stdout.strip()
    )
    # the test environment has torch; the install a user gets does not, so it is hidden from this one
    (site / "_hide_torch.py").write_text(HIDE_TORCH)
    (site / "zz_test_dependencies.pth").write_text(sysconfig.get_paths()["purelib"] + "\nimport _hide_torch\n")
    return env


def test_the_wheel_holds_one_namespace_and_the_shipped_model(wheel):
    names = zipfile.ZipFile(wheel).namelist()
    tops = {n.split("/")[0] for n in names if not n.split("/")[0].endswith(".dist-info")}
    assert tops == {"curve_vae"}
    for f in ("manifest.json", "encoder.onnx", "decoder.onnx", "prior.npz"):
        assert f"curve_vae/models/{f}" in names and f"curve_vae/models/paper/{f}" in names
    for page in ("index.html", "app.js", "files.js", "vase.js"):
        assert f"curve_vae/service/static/{page}" in names
    assert "curve_vae/curvefiles/svg.py" in names and "curve_vae/curvefiles/dxf.py" in names
    assert not [n for n in names if n.endswith(".pt")]  # torch weights are for training from a checkout
    # every file of the package is one of the tree's: nothing left over from an earlier build
    tree = set(tree_files())
    for name in names:
        if name.split("/")[0].endswith(".dist-info"):
            continue
        inside = name.removeprefix("curve_vae/")
        assert (inside if inside.split("/")[0] in MAPPED else name) in tree, name


def test_the_installed_command_tells_one_version(venv, tmp_path):
    from curve_vae import __version__

    out = subprocess.run(
        [str(venv / "bin" / "curve-vae"), "--version"], capture_output=True, text=True, cwd=tmp_path, check=True
    )
    assert out.stdout.strip() == f"curve-vae {__version__}"
    assert __version__ != "0.0.0"


def test_the_installed_wheel_serves_its_shipped_model_from_anywhere(venv, tmp_path):
    from curve_vae import __version__

    env = {k: v for k, v in os.environ.items() if not k.startswith("CURVE_VAE_")}
    # the wheel's own command, run from elsewhere, in an install without torch; one worker, as the tests' servers run
    # (a fresh install compiles its kernels in each worker: tests/service/test_server.py tests two)
    assert subprocess.run([str(venv / "bin" / "python"), "-c", "import torch"], capture_output=True).returncode != 0
    server = LiveServer("--workers", "1", command=[str(venv / "bin" / "curve-vae"), "serve"], cwd=tmp_path, env=env)
    try:
        server.wait_ready()
        url = server.url
        with urllib.request.urlopen(url + "/model") as r:
            model = json.load(r)
        shipped = json.loads((ROOT / "models" / "manifest.json").read_text())
        assert model["version"] == shipped["version"]  # the model's own version …
        assert model["service_version"] == __version__  # … beside the package's
        for graph in ("encoder.onnx", "decoder.onnx", "prior.npz"):  # checked against the files at load
            assert model["files"][graph]["sha256"] == shipped["files"][graph]["sha256"]
        with urllib.request.urlopen(url + "/openapi.json") as r:
            assert json.load(r)["info"]["version"] == __version__
        curve = [[float(x), float(x) ** 0.5 * 8] for x in range(0, 100, 5)]
        req = urllib.request.Request(
            url + "/reconstruct",
            data=json.dumps({"curves": [curve]}).encode(),
            headers={"Content-Type": "application/json"},
        )
        with urllib.request.urlopen(req) as r:
            answer = json.load(r)
        assert len(answer["curves"][0]) == len(curve)
    finally:
        server.stop()
