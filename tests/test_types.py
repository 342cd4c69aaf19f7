"""mypy over the package, as CI runs it: the whole suite runs in CI (.ci/run), so a type error fails the build.

Why a tree of links: the wheel maps folders onto one namespace with setuptools' package-dir (geometry/ is
curve_vae.geometry, inference/ is curve_vae.inference, ...; [tool.setuptools.package-dir] in pyproject.toml),
and mypy cannot read that mapping. Run over the folders as they lie, every `from curve_vae.inference import ...`
is unresolved and silently Any, and most of the cross-package calls go unchecked. So the test builds the
installed layout out of symlinks in a temporary dir (tmp/curve_vae/<each entry of curve_vae/>, plus
tmp/curve_vae/<sub> -> the folder package-dir names for curve_vae.<sub>) and checks `-p curve_vae` there, with
the repo's [tool.mypy] config. The failure message names the repo's files, not the links.
"""

import os
import shutil
import subprocess
import sys
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = "curve_vae"


def package_dirs() -> dict[str, Path]:
    """curve_vae.<sub> -> its folder in the repo, from pyproject's [tool.setuptools] package-dir."""
    with open(ROOT / "pyproject.toml", "rb") as f:
        mapping = tomllib.load(f)["tool"]["setuptools"]["package-dir"]
    dirs = {}
    for name, folder in mapping.items():
        head, _, sub = name.partition(".")
        assert head == PACKAGE and sub and "." not in sub, f"package-dir entry {name!r}: not {PACKAGE}.<sub>"
        dirs[sub] = ROOT / folder
    return dirs


def link_tree(tmp: Path) -> dict[Path, Path]:
    """Builds tmp/curve_vae as the installed package, in links; returns link -> repo path for each link."""
    pkg = tmp / PACKAGE
    pkg.mkdir()
    links = {}
    for entry in sorted((ROOT / PACKAGE).iterdir()):
        if entry.name != "__pycache__":
            links[pkg / entry.name] = entry
    for sub, folder in package_dirs().items():
        assert not (pkg / sub).exists() and pkg / sub not in links, f"{PACKAGE}/{sub} and package-dir both give it"
        links[pkg / sub] = folder
    for link, target in links.items():
        link.symlink_to(target, target_is_directory=target.is_dir())
    return links


def to_repo_paths(text: str, links: dict[Path, Path]) -> str:
    """The tmp paths in mypy's output, as the repo paths they link to (longest link first)."""
    for link in sorted(links, key=lambda p: len(str(p)), reverse=True):
        text = text.replace(str(link), str(links[link].relative_to(ROOT)))
    return text


def test_mypy_is_clean(tmp_path):
    # The tree of links lies at one place run after run, so mypy's cache (.mypy_cache, git-ignored) carries over:
    # a rerun checks only what changed (19 s cold, 1 s warm). A fresh clone starts cold.
    tree = ROOT / ".mypy_cache" / "package-dir-tree"
    shutil.rmtree(tree, ignore_errors=True)
    tree.mkdir(parents=True)
    links = link_tree(tree)
    command = [
        sys.executable,
        "-m",
        "mypy",
        "--config-file",
        str(ROOT / "pyproject.toml"),
        "--cache-dir",
        str(ROOT / ".mypy_cache"),
        "-p",
        PACKAGE,
    ]
    env = {**os.environ, "MYPYPATH": str(tree)}
    done = subprocess.run(command, cwd=tree, env=env, capture_output=True, text=True, timeout=600)
    # mypy names the files relative to cwd (curve_vae/geometry/bspline.py): as the repo paths, absolute first.
    relative = {link.relative_to(tree): target for link, target in links.items()}
    output = to_repo_paths(to_repo_paths(done.stdout + done.stderr, links), relative)
    assert done.returncode == 0, f"mypy -p {PACKAGE} (the package-dir layout in links):\n{output}"
