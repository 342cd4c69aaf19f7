"""The short version of bench/soak.py: a few seconds of mixed concurrent traffic, no error, bounded memory."""

from __future__ import annotations

import json

import pytest

from tests.helpers import SHIPPED

pytestmark = pytest.mark.integration


@pytest.mark.parametrize("fresh", [[], ["--fresh"]], ids=["mix", "fresh-curves"])
def test_short_soak_has_no_errors(tmp_path, capsys, fresh):
    from bench import soak

    out = tmp_path / "soak.json"
    args = ["--clients", "8", "--duration", "4", "--model-dir", str(SHIPPED), "--out", str(out), *fresh]
    assert soak.main(args) == 0, capsys.readouterr().out
    report = json.loads(out.read_text())
    assert report["errors"] == 0 and report["requests"] > 20 and report["bad_inputs_tried"] > 0
    assert len(report["by_kind"]) == 15  # every kind of the mix was sent
    assert report["server_exit_code"] == 0 and not report["server_log_has_traceback"]
