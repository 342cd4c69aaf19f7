"""curve_vae/commands/data.py: `curve-vae dataset` draws the data set of a configuration into its file once and reads
it back after; its --preview is a PNG, never replacing a user's file unless forced."""

from __future__ import annotations

import re

import numpy as np

from curve_vae.cli import main

SMALL = ["--n-train", "40", "--n-val", "8", "--n-test", "12", "--data-seed", "3"]
PNG = b"\x89PNG\r\n\x1a\n"


def test_the_data_set_is_drawn_once_into_its_file_and_read_back_after(tmp_path, capsys):
    data = tmp_path / "d.npz"
    assert main(["dataset", "--data", str(data), *SMALL]) == 0
    said = capsys.readouterr().out
    assert f"{data}: train (40, 161, 2), val (8, 161, 2), test (12, 161, 2)" in said
    lo, hi = map(float, re.search(r"coordinates in \[(\S+), (\S+)\]", said).groups())
    assert 0 <= lo < hi <= 128  # the paper's curves: control points in the disc of radius 64 about (64, 64)
    written = data.read_bytes()
    assert main(["dataset", "--data", str(data), *SMALL]) == 0
    assert f"{data}: train (40, 161, 2)" in capsys.readouterr().out and data.read_bytes() == written


def test_without_data_the_configuration_names_its_own_file(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    assert main(["dataset", *SMALL]) == 0
    assert main(["dataset", *SMALL[:-1], "4"]) == 0  # another seed, another file
    files = sorted((tmp_path / "data").glob("curves-*.npz"))
    assert len(files) == 2
    with np.load(files[0]) as a, np.load(files[1]) as b:
        assert not np.array_equal(a["train"], b["train"])


def test_a_data_file_of_another_configuration_is_refused_and_kept(tmp_path, capsys):
    data = tmp_path / "d.npz"
    assert main(["dataset", "--data", str(data), *SMALL]) == 0
    written = data.read_bytes()
    assert main(["dataset", "--data", str(data), "--n-train", "48", *SMALL[2:]]) == 2
    assert "n_train 40 (file) vs 48 (asked)" in capsys.readouterr().err
    assert data.read_bytes() == written


def test_the_preview_is_a_png_and_an_existing_one_is_kept_before_anything_is_drawn(tmp_path, capsys):
    data, preview = tmp_path / "d.npz", tmp_path / "grid.png"
    assert main(["dataset", "--data", str(data), *SMALL, "--preview", str(preview)]) == 0
    assert preview.read_bytes().startswith(PNG) and f"preview: {preview}" in capsys.readouterr().out
    mine = tmp_path / "mine.png"
    mine.write_bytes(b"the user's own picture")
    assert main(["dataset", "--data", str(tmp_path / "other.npz"), *SMALL, "--preview", str(mine)]) == 2
    assert "pass --force to replace it, or give another --preview" in capsys.readouterr().err
    assert mine.read_bytes() == b"the user's own picture" and not (tmp_path / "other.npz").exists()
    assert main(["dataset", "--data", str(data), *SMALL, "--preview", str(mine), "--force"]) == 0
    assert mine.read_bytes().startswith(PNG)
