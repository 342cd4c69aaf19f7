"""The models shipped with the package, by name, and how a model directory is named on the command line.

The package carries `models/` (the default) and `models/paper/` (the paper's own training) inside it, in a checkout
and in an installed wheel alike, so `--model paper` (or `CURVE_VAE_MODEL_DIR=paper`) works from anywhere.
"""

from __future__ import annotations

from pathlib import Path

#: The shipped models' directory: `models/` beside the inference package (in a checkout and in an install).
SHIPPED = Path(__file__).resolve().parents[2] / "models"
#: Names of the shipped models.
NAMED = {"default": SHIPPED, "paper": SHIPPED / "paper"}


def model_directory(value: str | Path | None) -> Path:
    """A model directory from a shipped model's name ("default", "paper"), a path, or None (the default)."""
    if value is None or str(value) == "":
        return SHIPPED
    text = str(value)
    if text in NAMED and not Path(text).is_dir():
        return NAMED[text]
    return Path(value)
