"""curve_vae.files: nothing of the user's replaced without --force (in every command that writes a file, and the
check itself), and files written whole or not at all (atomic_path, atomic_write_text, write_npy_chunks)."""

from __future__ import annotations

import json
import os
import stat

import numpy as np
import pytest

from curve_vae.cli import main
from curve_vae.errors import InvalidInput
from curve_vae.files import atomic_path, atomic_write_text, refuse_overwrite, write_npy_chunks
from curve_vae.geometry import random_control_points, sample_bspline


@pytest.fixture
def curve_file(tmp_path):
    ctrl = random_control_points(np.random.default_rng(0), 2)
    path = tmp_path / "curves.json"
    path.write_text(json.dumps({"curves": sample_bspline(ctrl).tolist()}))
    return path, ctrl


@pytest.mark.parametrize(
    "command",
    [
        pytest.param(["fit", "{src}", "-o", "{out}"], id="fit"),
        pytest.param(["revolve", "{profile}", "-o", "{out}"], id="revolve"),
        pytest.param(["sample", "--count", "2", "-o", "{out}"], id="sample"),
        pytest.param(["augment", "{src}", "--count", "2", "-o", "{out}"], id="augment"),
    ],
)
def test_no_command_overwrites_a_users_file_without_force(command, curve_file, tmp_path, capsys):
    path, _ = curve_file
    profile = tmp_path / "p.json"
    profile.write_text(json.dumps([[0, 0], [2, 0], [3, 1], [2, 3]]))
    out = tmp_path / "mine.json"
    out.write_text("the user's own file")
    args = [a.format(src=path, profile=profile, out=out) for a in command]
    assert main(args) == 2
    assert out.read_text() == "the user's own file"
    assert f"{out} exists and is left as it is: pass --force" in capsys.readouterr().err
    assert main([*args, "--force"]) == 0
    assert out.read_text() != "the user's own file"


@pytest.mark.parametrize("kind", ["file", "folder"])
def test_an_existing_path_is_refused_naming_it_and_the_flag(tmp_path, kind):
    path = tmp_path / "out"
    path.write_text("mine") if kind == "file" else path.mkdir()
    with pytest.raises(InvalidInput) as e:
        refuse_overwrite(path, force=False, flag="--preview")
    assert str(e.value) == f"{path} exists and is left as it is: pass --force to replace it, or give another --preview"


@pytest.mark.parametrize(
    ("name", "force"),
    [
        pytest.param("mine.json", True, id="forced"),
        pytest.param("new.json", False, id="not-there"),
        pytest.param("-", False, id="stdout"),
    ],
)
def test_a_forced_new_or_stdout_output_is_let_through(tmp_path, monkeypatch, name, force):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "mine.json").write_text("mine")
    (tmp_path / "-").write_text("a file named -: the output '-' is stdout, not it")
    refuse_overwrite(name, force=force)
    assert (tmp_path / "mine.json").read_text() == "mine"  # the check itself never touches a file


def test_an_atomic_path_appears_whole_readable_and_in_new_folders(tmp_path):
    target = tmp_path / "a" / "b" / "out.bin"
    with atomic_path(target) as tmp:
        assert tmp.parent == target.parent and tmp != target and not target.exists()
        tmp.write_bytes(b"\x00\x01")
    assert target.read_bytes() == b"\x00\x01"
    assert stat.S_IMODE(os.stat(target).st_mode) == 0o644
    assert sorted(p.name for p in target.parent.iterdir()) == ["out.bin"]


@pytest.mark.parametrize("under", ["out.npy", "sub/out.npy"])
def test_a_file_where_a_folder_should_be_is_named_and_left_alone(tmp_path, capsys, under):
    blocker = tmp_path / "results"
    blocker.write_text("a user's notes")
    assert main(["sample", "--count", "2", "-o", str(blocker / under)]) == 2
    err = capsys.readouterr().err
    assert f"cannot write {blocker / under}: {blocker} is a file, not a folder" in err and "Errno" not in err
    assert blocker.read_text() == "a user's notes" and [p.name for p in tmp_path.iterdir()] == ["results"]


def test_a_failed_write_leaves_the_old_file_and_no_temporary(tmp_path):
    target = tmp_path / "out.json"
    target.write_text("before")
    with pytest.raises(RuntimeError, match="disk full"), atomic_path(target) as tmp:
        tmp.write_text("half of the new")
        raise RuntimeError("disk full")
    assert target.read_text() == "before"
    assert [p.name for p in tmp_path.iterdir()] == ["out.json"]


def test_atomic_write_text_replaces_the_files_text(tmp_path):
    target = tmp_path / "out.txt"
    target.write_text("a much longer text than the one that replaces it")
    atomic_write_text(target, "short ✓")
    assert target.read_text() == "short ✓"


def test_npy_chunks_make_the_float32_array_numpy_loads(tmp_path):
    rng = np.random.default_rng(0)
    parts = [rng.normal(size=(n, 5, 2)) for n in (3, 1, 4)]
    path = tmp_path / "c.npy"
    write_npy_chunks(str(path), (8, 5, 2), iter(parts))
    got = np.load(path)
    assert got.dtype == np.float32 and got.shape == (8, 5, 2)
    np.testing.assert_array_equal(got, np.concatenate(parts).astype(np.float32))
    assert [p.name for p in tmp_path.iterdir()] == ["c.npy"]


def test_npy_chunks_short_of_the_shape_leave_no_file(tmp_path):
    path = tmp_path / "c.npy"
    with pytest.raises(InvalidInput, match="chunks gave 3 rows, the header promised 8"):
        write_npy_chunks(str(path), (8, 5, 2), [np.zeros((3, 5, 2))])
    assert list(tmp_path.iterdir()) == []
