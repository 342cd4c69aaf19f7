"""The docs as a site: `mkdocs build --strict` passes (every link, anchor and figure resolves, the Python API renders
from its docstrings), and the pages stay readable — short pages outside the history, RESULTS.md opening with its
summary table, every script a page cites present, no README paragraph past 8 lines, the settings page naming every
setting, Get started showing the README's two commands."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"

#: The pages a reader meets first: every docs page but the version-by-version history, and the README.
CURRENT = sorted(p for p in DOCS.rglob("*.md") if "history" not in p.relative_to(DOCS).parts)
MAX_PAGE_LINES = 400
MAX_PARAGRAPH_LINES = 8
#: A script path as the docs cite it (`scripts/x.py`, `bench/x.py`, `python -m bench.x`), not part of a longer path.
SCRIPT = re.compile(r"(?<![\w/.-])((?:scripts|bench)/[\w/-]+\.(?:py|sh))|python -m (bench\.[\w.]+)")


def test_the_site_builds_strictly(tmp_path):
    site = tmp_path / "site"
    out = subprocess.run(
        [sys.executable, "-m", "mkdocs", "build", "--strict", "--site-dir", str(site)],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=300,
        env={**os.environ, "NO_MKDOCS_2_WARNING": "1"},
    )
    assert out.returncode == 0, out.stdout[-3000:] + out.stderr[-3000:]
    assert (site / "index.html").is_file() and (site / "PYTHON" / "index.html").is_file()
    python_api = (site / "PYTHON" / "index.html").read_text()
    assert 'id="curve_vae.client.Client.reconstruct"' in python_api  # docstrings rendered, not just headings
    assert not (ROOT / "site").exists(), "the build went into the tree"


def test_every_page_outside_the_history_is_short():
    assert CURRENT, "no docs pages found"
    long = {str(p.relative_to(ROOT)): n for p in CURRENT if (n := len(p.read_text().splitlines())) > MAX_PAGE_LINES}
    assert not long, f"pages past {MAX_PAGE_LINES} lines (move version-by-version notes to docs/history/): {long}"


def test_every_page_is_in_the_sites_nav():
    nav = (ROOT / "mkdocs.yml").read_text()
    missing = [str(p.relative_to(DOCS)) for p in DOCS.rglob("*.md") if str(p.relative_to(DOCS)) not in nav]
    assert not missing, missing


def test_results_open_with_the_summary_table():
    head = (DOCS / "RESULTS.md").read_text().splitlines()[:40]
    assert any(line.startswith("|") for line in head), "docs/RESULTS.md must show its summary table in 40 lines"


def test_every_cited_script_exists():
    missing = set()
    for page in [*CURRENT, ROOT / "README.md"]:
        for path, module in SCRIPT.findall(page.read_text()):
            cited = ROOT / path if path else ROOT / (module.replace(".", "/") + ".py")
            if not cited.is_file():
                missing.add(f"{page.relative_to(ROOT)}: {path or module}")
    assert not missing, sorted(missing)


def _paragraphs(text: str) -> list[list[str]]:
    """Blocks of consecutive non-blank lines outside code fences, tables and headings."""
    blocks: list[list[str]] = [[]]
    fenced = False
    for line in text.splitlines():
        if line.startswith("```"):
            fenced = not fenced
            blocks.append([])
        elif fenced or not line.strip() or line.startswith(("|", "#")):
            blocks.append([])
        else:
            blocks[-1].append(line)
    return [b for b in blocks if b]


def test_no_readme_paragraph_runs_past_eight_lines():
    long = [b[0][:60] for b in _paragraphs((ROOT / "README.md").read_text()) if len(b) > MAX_PARAGRAPH_LINES]
    assert not long, f"README paragraphs past {MAX_PARAGRAPH_LINES} lines, starting: {long}"


def test_get_started_shows_the_readmes_two_commands():
    def first_bash(text: str) -> str:
        return text.split("```bash", 1)[1].split("```", 1)[0]

    assert first_bash((DOCS / "index.md").read_text()) == first_bash((ROOT / "README.md").read_text())


def test_the_settings_page_names_every_setting():
    from curve_vae.service.settings import Settings

    page = (DOCS / "SETTINGS.md").read_text()
    missing = [name for name in Settings.model_fields if f"CURVE_VAE_{name.upper()}`" not in page]
    assert not missing, missing


def test_the_versions_named_are_the_packages_and_the_models():
    import json
    import tomllib

    package = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["version"]
    model = json.loads((ROOT / "models" / "manifest.json").read_text())["version"]
    for page in (ROOT / "README.md", DOCS / "index.md"):
        text = page.read_text()
        assert package in text and model in text, f"{page.name} names another package or model version"
