"""openapi.yaml at the repository root: the app's own schema, written by `python -m curve_vae.service.openapi`.

A test regenerates it and fails when the committed file drifts from the app.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

ROOT_FILE = Path(__file__).resolve().parent.parent / "openapi.yaml"


def openapi_spec() -> dict[str, Any]:
    """The schema of an app with default settings; the environment and the model play no part."""
    from curve_vae.service.app import create_app
    from curve_vae.service.settings import Settings

    return create_app(Settings.model_construct()).openapi()


def render() -> str:
    """YAML for people: multi-line text as literal blocks, lists of numbers (points, latents) on one line."""
    import yaml  # a development dependency: the service itself never needs it

    class Dumper(yaml.SafeDumper):
        pass

    def text(dumper: yaml.SafeDumper, value: str) -> yaml.Node:
        return dumper.represent_scalar("tag:yaml.org,2002:str", value, style="|" if "\n" in value else None)

    def sequence(dumper: yaml.SafeDumper, value: list[Any]) -> yaml.Node:
        flat = all(isinstance(v, int | float | str) and not isinstance(v, bool) for v in value)
        return dumper.represent_sequence("tag:yaml.org,2002:seq", value, flow_style=flat and bool(value))

    Dumper.add_representer(str, text)
    Dumper.add_representer(list, sequence)
    return yaml.dump(openapi_spec(), Dumper=Dumper, sort_keys=False, allow_unicode=True, width=120)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description="Write the service's OpenAPI schema as YAML.")
    parser.add_argument("--out", type=Path, default=ROOT_FILE, help=f"output file (default: {ROOT_FILE})")
    parser.add_argument("--check", action="store_true", help="exit 1 if the file differs instead of writing it")
    args = parser.parse_args(argv)
    text = render()
    if args.check:
        same = args.out.is_file() and args.out.read_text() == text
        print(f"{args.out}: {'up to date' if same else 'out of date; run python -m curve_vae.service.openapi'}")
        return 0 if same else 1
    args.out.write_text(text)
    print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
