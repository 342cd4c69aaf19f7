"""What the default reading costs against one encoding, on a real server, this checkout's and another revision's in
one run: the default request's rate over one encoding's (`"pose": "canonical", "spacing": "parameter"`, no look
again) for 128-curve requests on 2 connections (A) and single curves on 16 (B), each server started afresh with the
encoding cache off and driven by wrk.

    .venv/bin/python -m bench.reading_cost --against 9d74e6d            # service 0.26.0 beside this checkout
    .venv/bin/python -m bench.reading_cost --against 9d74e6d --seconds 30 --json out.json

The other revision runs from its own files (git archive into the system's temporary directory, laid out as the
package's folders) with this checkout's interpreter and libraries; the two servers run one after the other on the
same cores, so compare the ratios of one run.
"""

from __future__ import annotations

import argparse
import io
import json
import os
import subprocess
import sys
import tarfile
from pathlib import Path
from typing import Any

from bench.ceiling import posted
from bench.revisions import ROOT, SCRATCH
from bench.serve import NO_CACHE, json_body, machine, wrk
from curve_vae.inference.model.cpus import available_cpus
from curve_vae.service.live import LiveServer

#: The folders installed as the package's sub-packages (pyproject.toml's package-dir).
MAPPED = ("geometry", "inference", "service", "training", "models")


def revision_root(revision: str) -> Path:
    """The revision's files, with a folder `curve_vae` laid out as the installed package (its own modules, and its
    mapped folders beside them), to put first on the path."""
    out = SCRATCH / f"curve-vae-{revision}"
    if not out.exists():
        archive = subprocess.run(["git", "archive", revision], cwd=ROOT, capture_output=True, check=True).stdout
        with tarfile.open(fileobj=io.BytesIO(archive)) as tar:
            tar.extractall(out / "tree", filter="data")
        package = out / "curve_vae"
        package.mkdir()
        for entry in (out / "tree" / "curve_vae").iterdir():
            (package / entry.name).symlink_to(entry)
        for name in MAPPED:
            (package / name).symlink_to(out / "tree" / name)
    return out


class RevisionServer(LiveServer):
    """`python -m curve_vae.service.server` of this checkout (revision None) or of another revision, on the shipped
    model it ships, cache off, ready when made."""

    def __init__(self, revision: str | None) -> None:
        root = ROOT if revision is None else revision_root(revision)
        env = dict(NO_CACHE)
        if revision is not None:
            env["PYTHONPATH"] = str(root)  # before this checkout's editable install
        models = ROOT / "models" if revision is None else root / "tree" / "models"
        super().__init__("--model-dir", str(models), "--providers", "cpu", env=env, cwd=root, capture=False)
        try:
            self.wait_ready(workers=available_cpus())
        except BaseException:
            self.stop()
            raise


def measure(revision: str | None, one_encoding: dict[str, Any], seconds: float) -> dict[str, Any]:
    """A and B with default fields and with one encoding's, against one server."""
    single, many = posted(1, seed=1), posted(128, seed=2)
    server = RevisionServer(revision)
    try:
        wrk(server, "/reconstruct", json_body(single), "application/json", connections=16, seconds=2)  # warmed up
        out = {}
        for name, curves, connections in (("A", many, 2), ("B", single, 16)):
            for suffix, fields in (("", {}), ("_one", one_encoding)):
                print(f"{revision or 'this checkout'}: {name}{suffix} ...", file=sys.stderr)
                r = wrk(server, "/reconstruct", json_body(curves, **fields), "application/json",
                        connections=connections, seconds=seconds)  # fmt: skip
                out[name + suffix] = {"rps": r["rps"], "curves_per_s": r["rps"] * len(curves), "p50_ms": r["p50_ms"],
                                      "server_cpu_ms_per_request": r["server_cpu_ms_per_request"],
                                      "errors": r["errors"] + r["non_2xx"]}  # fmt: skip
        out["A_over_one"] = out["A"]["rps"] / out["A_one"]["rps"]
        out["B_over_one"] = out["B"]["rps"] / out["B_one"]["rps"]
        return out
    finally:
        server.stop()


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--against", required=True, help="the revision to measure beside this checkout")
    p.add_argument("--seconds", type=float, default=20.0, help="each wrk run (default 20)")
    p.add_argument("--json", default="", help="also write the report here")
    a = p.parse_args()
    one = {"pose": "canonical", "spacing": "parameter"}
    report: dict[str, Any] = {"machine": machine(), "seconds": a.seconds, "command": " ".join(sys.argv)}
    report["against"] = {"revision": a.against, **measure(a.against, one, a.seconds)}
    report["this checkout"] = measure(None, {**one, "looks": 0}, a.seconds)
    print("| server | A: default / one encoding | B: default / one encoding | A curves/s | B requests/s |")
    print("|---|---|---|---|---|")
    for name in ("against", "this checkout"):
        r = report[name]
        print(f"| {name} | {r['A_over_one']:.2f} | {r['B_over_one']:.2f} | {r['A']['curves_per_s']:.0f} | "
              f"{r['B']['rps']:.0f} |")  # fmt: skip
    if a.json:
        Path(a.json).write_text(json.dumps(report, indent=2))


if __name__ == "__main__":
    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
    main()
