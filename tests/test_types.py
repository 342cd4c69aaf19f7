"""mypy over the packages, as CI runs it: the whole suite runs in CI (.ci/run), so a type error fails the build.

The same paths and config ([tool.mypy] in pyproject.toml) as `python -m mypy geometry inference service curve_vae`.
"""

import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PATHS = ["geometry", "inference", "service", "curve_vae"]


def test_mypy_is_clean():
    done = subprocess.run([sys.executable, "-m", "mypy", *PATHS], cwd=ROOT, capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, f"mypy {' '.join(PATHS)}:\n{done.stdout}{done.stderr}"
