"""The short version of scripts/soak.py: a few seconds of mixed concurrent traffic, no error, bounded memory."""

from __future__ import annotations

import importlib.util
import json

import pytest

from tests.helpers import ROOT, SHIPPED

pytestmark = pytest.mark.integration


def test_short_soak_has_no_errors(tmp_path, capsys):
    spec = importlib.util.spec_from_file_location("soak", ROOT / "scripts" / "soak.py")
    soak = importlib.util.module_from_spec(spec)  # type: ignore[arg-type]
    spec.loader.exec_module(soak)  # type: ignore[union-attr]
    out = tmp_path / "soak.json"
    args = ["--clients", "8", "--duration", "4", "--model-dir", str(SHIPPED), "--out", str(out)]
    assert soak.main(args) == 0, capsys.readouterr().out
    report = json.loads(out.read_text())
    assert report["errors"] == 0 and report["requests"] > 20 and report["bad_inputs_tried"] > 0
    assert len(report["by_kind"]) == 15  # every kind of the mix was sent
    assert report["server_exit_code"] == 0 and not report["server_log_has_traceback"]
