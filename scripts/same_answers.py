"""Whether this checkout answers as another revision does, bit for bit: the family suite (training.suite, 40 curves a
set) through each revision's app, in process, the encoding cache off: the default /reconstruct of every curve,
`"refine": 2` of the first 8, 8 pair sweeps of 5 steps, and 40 /augment curves from the first 10. Prints the answers
that differ (by the sha256 of each response body) and, for each revision, the answers that cross themselves
(/reconstruct: where its input does not; in-betweens and augmented curves: at all).

    .venv/bin/python scripts/same_answers.py --against 82a174e      # ~1 minute on 2 cores

The other revision runs from its own files (bench.reading_cost.revision_root) with this checkout's interpreter.
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

#: Run inside each revision's process: prints {"hashes": {answer: sha256}, "crossing": {kind: count}}.
ANSWERS = """
import hashlib, json
import numpy as np
from fastapi.testclient import TestClient
from curve_vae.geometry import self_intersects
from curve_vae.geometry.validity import new_crossings
from curve_vae.service.app import create_app
from curve_vae.training.suite import paper_test_split, suite_sets

hashes, crossing = {}, {"reconstruct": 0, "refine": 0, "in-betweens": 0, "augment": 0}
def post(client, key, path, body):
    r = client.post(path, json=body)
    assert r.status_code == 200, (key, r.text)
    hashes[key] = hashlib.sha256(r.content).hexdigest()
    return [np.asarray(c) for c in r.json()["curves"]]
with TestClient(create_app()) as client:
    for name, (_, curves) in suite_sets(paper_test_split(), count=40, seed=2024).items():
        given = [np.asarray(c, np.float64) for c in curves]
        lists = [c.tolist() for c in given]
        got = post(client, f"{name}/reconstruct", "/reconstruct", {"curves": lists})
        crossing["reconstruct"] += int(np.sum(new_crossings(given, got)))
        got = post(client, f"{name}/refine 2", "/reconstruct", {"curves": lists[:8], "refine": 2})
        crossing["refine"] += int(np.sum(new_crossings(given[:8], got)))
        for k in range(0, 16, 2):
            got = post(client, f"{name}/pair {k}", "/interpolate", {"curves": lists[k : k + 2], "steps": 5})
            crossing["in-betweens"] += int(np.sum(self_intersects(np.stack(got))))
        got = post(client, f"{name}/augment", "/augment", {"curves": lists[:10], "count": 40, "seed": 1})
        crossing["augment"] += int(np.sum(self_intersects(np.stack(got))))
print(json.dumps({"hashes": hashes, "crossing": crossing}))
"""


def answers(revision: str | None) -> dict:
    env = {**os.environ, "CURVE_VAE_CACHE_BYTES": "0", "OPENBLAS_NUM_THREADS": "1"}
    cwd = ROOT
    if revision is not None:
        from bench.reading_cost import revision_root

        root = revision_root(revision)
        cwd = root / "tree"
        env |= {"PYTHONPATH": str(root), "CURVE_VAE_MODEL_DIR": str(cwd / "models")}
        for wheel in (ROOT / "data").glob("aerosandbox-*.whl"):  # the airfoil set's source, where this checkout has it
            (cwd / "data").mkdir(exist_ok=True)
            shutil.copy2(wheel, cwd / "data" / wheel.name)
    done = subprocess.run([sys.executable, "-c", ANSWERS], cwd=cwd, env=env, capture_output=True, text=True)
    if done.returncode != 0:
        raise SystemExit(f"{revision or 'this checkout'}: {done.stderr[-3000:]}")
    return json.loads(done.stdout.strip().splitlines()[-1])


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--against", required=True, help="the revision to compare this checkout's answers with")
    a = p.parse_args()
    sys.path.insert(0, str(ROOT))
    theirs, ours = answers(a.against), answers(None)
    differ = sorted(k for k in ours["hashes"] if ours["hashes"][k] != theirs["hashes"].get(k))
    print(f"{len(ours['hashes'])} answers, {len(differ)} differ from {a.against}'s" + (f": {differ}" if differ else ""))
    print(f"crossing themselves, {a.against}: {theirs['crossing']}")
    print(f"crossing themselves, this checkout: {ours['crossing']}")
    raise SystemExit(1 if differ else 0)


if __name__ == "__main__":
    main()
