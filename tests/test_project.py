"""The README's set-up commands stay true: CI runs exactly the README's test command."""

from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def _readme_commands() -> list[str]:
    text = (ROOT / "README.md").read_text()
    block = text.split("```bash", 1)[1].split("```", 1)[0]
    return [line for line in block.splitlines() if line.strip() and not line.startswith("#")]


def test_readme_opens_with_run_and_test_commands():
    run, test = _readme_commands()[:2]
    assert "curve-vae serve" in run
    assert "pytest" in test


def test_ci_runs_the_readme_test_command():
    ci = (ROOT / ".ci" / "run").read_text()
    assert _readme_commands()[1] in ci.splitlines()


def test_every_package_folder_is_in_the_one_namespace_the_wheel_installs():
    import tomllib

    tool = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]
    listed, dirs = set(tool["packages"]), tool["package-dir"]
    roots = {"curve_vae": ROOT / "curve_vae", **{name: ROOT / path for name, path in dirs.items()}}
    found = set()
    for name, root in roots.items():
        for init in root.rglob("__init__.py"):
            found.add(".".join([name, *init.parent.relative_to(root).parts]))
    assert found <= listed, f"package folders missing from pyproject's packages: {sorted(found - listed)}"
    assert all(n == "curve_vae" or n.startswith("curve_vae.") for n in listed)


def test_the_service_tests_import_no_torch():
    """tests/service, tests/e2e and tests/bench run in the service's install (no torch): their models are committed."""
    import ast

    for path in [p for folder in ("service", "e2e", "bench") for p in (ROOT / "tests" / folder).rglob("*.py")]:
        for node in ast.walk(ast.parse(path.read_text())):
            names = (
                [a.name for a in node.names]
                if isinstance(node, ast.Import)
                else [node.module or ""]
                if isinstance(node, ast.ImportFrom)
                else []
            )
            for name in names:
                assert name.split(".")[0] != "torch", f"{path.name}:{node.lineno} imports {name}"
                assert not name.startswith(("curve_vae.training.model", "curve_vae.training.export")), (
                    f"{path.name}:{node.lineno} imports {name}, which needs torch"
                )
