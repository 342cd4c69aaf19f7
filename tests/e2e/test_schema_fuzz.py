"""Schemathesis against the live service: every check, positive and negative data, examples + coverage + fuzzing.

The published schema states every bound JSON Schema can express (service.openapi.state_bounds), so the only
failures allowed are the rules that combine fields or look at the numbers' geometry, named one by one below.
"""

from __future__ import annotations

import re
import subprocess
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

from tests.helpers import SHIPPED, spawn_server

pytestmark = pytest.mark.integration

#: Rules JSON Schema cannot state, each with the message the service answers (a 422 naming the fields).
CROSS_FIELD_RULES = {
    "coincident points": r"all \d+ points coincide: a curve needs at least 2 distinct points",
    "segments × profile points ≤ CURVE_VAE_MAX_MESH_TRIANGLES": r"segments of a \d+-point profile make up to",
    "refine steps × input points ≤ CURVE_VAE_MAX_REFINE_WORK": r"point-steps; at most \d+ \(CURVE_VAE_MAX_REFINE_WORK",
    "neighbours ≥ the sources per mode - 1": r"neighbours: mode \w+ mixes each curve with \d others",
    "neighbours ≤ the number of other curves": r"neighbours: at most \d+ \(each curve has",
    "one frame per latent": r"frames: expected one frame per latent",
    "triplet steps: steps·(steps+1)/2 ≤ CURVE_VAE_MAX_CURVES": r"steps over \d+ curves make \d+ curves",
    "count ≤ CURVE_VAE_MAX_CURVES with format json": r"count: at most \d+, got \d+ \(format json",
    "triplets need 3 curves": r"mode triplet needs at least 3 curves",
    "one weight per curve, rows summing to 1": r"weights\[\d+\]: ",
    "n_ctrl ≤ the curve's points": r"n_ctrl=\d+ control points need at least as many points",
    "a spline fit needs spread points": r"no unique least-squares spline",
    "metrics and output only with format json": r"(metrics|output): only",
    "coordinates the model's frame cannot hold": r"(too small or too large|beyond float32 range|non-finite|float64)",
    "a profile must stay on one side of the axis": r"axis",
    "a prior the server has loaded (GET /model: priors)": r"prior: no prior named",
    "explore: steps**directions ≤ 256 curves": r"steps\*\*directions curves would be \d+; at most 256",
}
#: The same for the Open Inference Protocol (/v2), which answers a request that does not fit the model's tensors
#: with the protocol's 400 and `{"error": ...}` instead of a 422.
OIP_CROSS_FIELD_RULES = {
    "a tensor's data holds the product of its shape": r"numbers, but shape \[[\d, ]+\] holds \d+",
    "numbers far outside the model's plane give non-finite outputs": r"is not finite for batch row \d+",
}


def test_schemathesis_finds_nothing_but_the_named_cross_field_rules(tmp_path):
    server = spawn_server("--model-dir", str(SHIPPED), "--providers", "cpu")
    try:
        server.wait_ready()
        junit = tmp_path / "junit.xml"
        st = str(Path(sys.executable).parent / "st")
        run = subprocess.run(
            [
                st,
                "run",
                f"{server.url}/openapi.json",
                "--checks",
                "all",
                "--mode",
                "all",
                "--phases",
                "examples,coverage,fuzzing",
                "--max-examples",
                "15",
                "--seed",
                "1",
                "-w",
                "2",
                "--request-timeout",
                "60",
                "--report",
                "junit",
                "--report-junit-path",
                str(junit),
            ],  # fmt: skip
            capture_output=True,
            text=True,
            timeout=600,
        )
    finally:
        server.stop()
    assert junit.exists(), run.stdout[-3000:] + run.stderr[-3000:]
    failures = [
        (case.get("name"), child.text or "")
        for case in ET.parse(junit).iter("testcase")
        for child in case
        if child.tag in ("failure", "error")
    ]
    unexplained = []
    for name, text in failures:
        if text.startswith("Runtime Error") and "site-packages/schemathesis/" in text:
            # the tool's own generator broke on this operation (now and then, in its coverage phase): no finding
            # about the service, and its other phases and operations still ran
            continue
        if "ST202 Schema-valid request rejected" in text and "[422]" in text:
            if any(re.search(rule, text) for rule in CROSS_FIELD_RULES.values()):
                continue
        if "ST202 Schema-valid request rejected" in text and "[400]" in text and '{"error":' in text:
            if any(re.search(rule, text) for rule in OIP_CROSS_FIELD_RULES.values()):
                continue
        unexplained.append(f"{name}: {text[:1500]}")
    assert unexplained == [], "\n\n".join(unexplained)
    assert "generated" in run.stdout  # it ran: test cases were generated and sent
