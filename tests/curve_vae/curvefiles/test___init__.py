"""curve_vae.curvefiles (the package's read_curves and read_curve_files): a file by its extension, numpy arrays by
name, standard input, and a folder of curve files read whole, what is not a curve file named in a warning and a file
that cannot be read named in the error."""

from __future__ import annotations

import io
import json
import sys
import warnings

import numpy as np
import pytest

from curve_vae.curvefiles import CurveFileError, CurveFileWarning, read_curve_files, read_curves
from tests.helpers import FIXTURES

FILES = FIXTURES / "files"
SQUARE_WAVE = [[0, 0], [1, 1], [2, 0], [3, 1]]


def test_a_folder_of_airfoils_with_notes_is_read_whole(tmp_path):
    for f in FILES.glob("*.dat"):
        (tmp_path / f.name).write_text(f.read_text())
    (tmp_path / "README.txt").write_text("where these came from")
    (tmp_path / ".ipynb_checkpoints").mkdir()
    (tmp_path / ".ipynb_checkpoints" / "half-saved.json").write_text("[[0, 0], [1,")  # hidden: not the user's curves
    with pytest.warns(CurveFileWarning, match=r"1 file\(s\) not of a curve kind skipped: README\.txt"):
        curves = read_curve_files(tmp_path)
    assert len(curves) == 5 and all(len(c) == 69 for c in curves)


def test_npz_arrays_by_name(tmp_path):
    np.savez(tmp_path / "c.npz", curves=np.zeros((3, 5, 2)), other=np.zeros(4))
    assert len(read_curves(tmp_path / "c.npz")) == 3
    np.savez(tmp_path / "prior.npz", weights=np.ones(2), means=np.zeros((2, 32)))
    with pytest.raises(CurveFileError, match=r"prior\.npz: no array of shape \(n, 2\)"):
        read_curves(tmp_path / "prior.npz")


def test_a_folder_names_the_file_it_cannot_read(tmp_path):
    (tmp_path / "a.json").write_text("[[0,0],[1,1],[2,0],[3,1]]")
    (tmp_path / "b.csv").write_text("0,0\n1,x\n")
    with pytest.raises(CurveFileError, match=r"b\.csv:2"):
        read_curve_files(tmp_path)


def test_npy_curves_one_or_many(tmp_path):
    np.save(tmp_path / "one.npy", np.array(SQUARE_WAVE, np.float32))
    np.save(tmp_path / "many.npy", np.stack([SQUARE_WAVE, np.add(SQUARE_WAVE, 1)]).astype(np.int64))
    (one,) = read_curves(tmp_path / "one.npy")
    np.testing.assert_array_equal(one, SQUARE_WAVE)
    assert [c.tolist() for c in read_curves(tmp_path / "many.npy")] == [SQUARE_WAVE, np.add(SQUARE_WAVE, 1).tolist()]


def test_an_npz_without_curves_gives_every_array_of_their_shape_by_name(tmp_path):
    b, a = np.add(SQUARE_WAVE, 5), np.array(SQUARE_WAVE)
    np.savez(tmp_path / "c.npz", b=b, a=a, latents=np.zeros((3, 32)), labels=np.array(["x", "y"]))
    got = read_curves(tmp_path / "c.npz")
    assert [c.tolist() for c in got] == [a.tolist(), b.tolist()]  # a before b: sorted by name


@pytest.mark.parametrize(
    ("name", "write", "message"),
    [
        pytest.param("c.npy", lambda p: np.save(p, np.zeros((5, 3))),
                     r"c\.npy: an array of shape \(5, 3\); curves are \(n, 2\) or \(N, n, 2\)", id="npy-shape"),
        pytest.param("c.npy", lambda p: p.write_text("[[0, 0]]"), r"c\.npy: not a numpy file", id="npy-text"),
        pytest.param("c.npz", lambda p: p.write_bytes(b"PK but not a zip"), r"c\.npz: not a numpy file", id="npz-junk"),
        pytest.param("c.npy", lambda p: p.write_bytes(b"PK\x03\x04 a broken zip"), r"c\.npy: not a numpy file",
                     id="zip-junk"),
        pytest.param("gone.json", None, r"gone\.json: no such file", id="missing"),
        pytest.param("drawings", lambda p: p.mkdir(), r"drawings: a folder; this command reads one curve file",
                     id="folder"),
    ],
)  # fmt: skip
def test_a_file_that_is_not_curves_names_itself(tmp_path, name, write, message):
    if write is not None:
        write(tmp_path / name)
    with pytest.raises(CurveFileError, match=message):
        read_curves(tmp_path / name)


def test_an_unknown_extension_or_stdin_is_read_as_json(tmp_path, monkeypatch):
    (tmp_path / "curves.points").write_text(json.dumps({"curves": [SQUARE_WAVE]}))
    np.testing.assert_array_equal(read_curves(tmp_path / "curves.points")[0], SQUARE_WAVE)
    monkeypatch.setattr(sys, "stdin", io.StringIO(str(SQUARE_WAVE)))
    np.testing.assert_array_equal(read_curves("-")[0], SQUARE_WAVE)


def test_an_upper_case_extension_is_its_kind(tmp_path):
    (tmp_path / "C.CSV").write_text("x,y\n" + "".join(f"{x},{y}\n" for x, y in SQUARE_WAVE))
    np.testing.assert_array_equal(read_curves(tmp_path / "C.CSV")[0], SQUARE_WAVE)


def test_a_folder_is_read_in_path_order_through_its_subfolders(tmp_path):
    (tmp_path / "b").mkdir()
    (tmp_path / "b" / "2.json").write_text(str([np.add(SQUARE_WAVE, 2).tolist()]))
    (tmp_path / "a.json").write_text(str([SQUARE_WAVE]))
    (tmp_path / "c.csv").write_text("".join(f"{x + 3},{y}\n" for x, y in SQUARE_WAVE))
    got = read_curve_files(tmp_path)
    assert [c[0, 0] for c in got] == [0, 2, 3]


@pytest.mark.parametrize(
    ("make", "message"),
    [
        pytest.param(
            lambda d: (d / "notes.md").write_text("no curves"), r"no curve files \(\.json, ", id="no-curve-file"
        ),
        pytest.param(lambda d: None, r"no curve files", id="empty-folder"),
    ],
)  # fmt: skip
def test_a_folder_without_curve_files_is_an_error(tmp_path, make, message):
    make(tmp_path)
    with warnings.catch_warnings(), pytest.raises(CurveFileError, match=message):
        warnings.simplefilter("ignore", CurveFileWarning)  # notes.md is named in one: the folder's other test says so
        read_curve_files(tmp_path)


def test_a_path_that_is_not_there_is_named(tmp_path):
    with pytest.raises(CurveFileError, match=r"nowhere: no such file or directory"):
        read_curve_files(tmp_path / "nowhere")
