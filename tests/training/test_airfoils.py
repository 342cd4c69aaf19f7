"""training/airfoils.py: airfoil coordinate files read from a folder or from the database folder of aerosandbox's
wheel; the files that parse, have enough points and span both axes are drawn from, seeded."""

from __future__ import annotations

import zipfile

import numpy as np
import pytest

from curve_vae.errors import InvalidInput
from curve_vae.training.airfoils import DATABASE, airfoil_texts, load_airfoils


def _dat(name: str, points: np.ndarray) -> str:
    return name + "\n" + "\n".join(f"{x:.6f} {y:.6f}" for x, y in points) + "\n"


def _airfoil(n: int, thickness: float) -> np.ndarray:
    """A closed-looking airfoil in Selig order: trailing edge, upper side, leading edge, lower side, trailing edge."""
    t = np.linspace(0, 2 * np.pi, n)
    return np.stack([(1 + np.cos(t)) / 2, thickness * np.sin(t)], 1)


FILES = {
    "a.dat": _dat("A", _airfoil(30, 0.12)),
    "b.dat": _dat("B", _airfoil(25, 0.08)),
    "short.dat": _dat("SHORT", _airfoil(10, 0.1)),  # fewer than 20 points
    "flat.dat": _dat("FLAT", np.stack([np.linspace(0, 1, 30), np.zeros(30)], 1)),  # no height
    "notes.dat": "NOTES\nthis file holds words, not coordinates\n",
}


@pytest.fixture
def folder(tmp_path):
    out = tmp_path / "db"
    (out / "sub").mkdir(parents=True)
    for name, text in FILES.items():
        (out / ("sub" if name == "b.dat" else "") / name).write_text(text)
    (out / "readme.txt").write_text("not a .dat file")
    return out


def test_a_folders_dat_files_are_read_nested_ones_too(folder):
    texts = airfoil_texts(folder)
    assert sorted(texts) == sorted(FILES) and texts["b.dat"] == FILES["b.dat"]


def test_a_wheels_database_folder_is_read_and_nothing_else_of_it(tmp_path):
    wheel = tmp_path / "aerosandbox-0-py3-none-any.whl"
    with zipfile.ZipFile(wheel, "w") as z:
        for name, text in FILES.items():
            z.writestr(DATABASE + name, text)
        z.writestr("aerosandbox/other/elsewhere.dat", FILES["a.dat"])
        z.writestr(DATABASE + "readme.txt", "not a .dat file")
    assert airfoil_texts(wheel) == FILES


def test_any_other_source_is_refused_by_name(tmp_path):
    with pytest.raises(InvalidInput, match="x.tar: expected a directory of .dat files or aerosandbox's wheel"):
        airfoil_texts(tmp_path / "x.tar")


def test_only_files_that_parse_with_enough_points_and_height_are_drawn_from(folder):
    curves = load_airfoils(folder, count=10)
    assert [len(c) for c in curves] == [30, 25]  # a.dat, then sub/b.dat; short, flat and notes left out
    np.testing.assert_allclose(curves[0], _airfoil(30, 0.12), atol=1e-6)
    assert sorted(len(c) for c in load_airfoils(folder, count=10, min_points=10)) == [10, 25, 30]


def test_the_draw_is_seeded_and_keeps_the_files_order(folder):
    # drawn from a.dat (30 points), short.dat (10), sub/b.dat (25), in the order of their paths
    draws = {seed: [len(c) for c in load_airfoils(folder, count=2, seed=seed, min_points=10)] for seed in range(8)}
    assert {tuple(d) for d in draws.values()} <= {(30, 10), (30, 25), (10, 25)}
    assert len({tuple(d) for d in draws.values()}) > 1  # the seed picks
    again = [len(c) for c in load_airfoils(folder, count=2, seed=3, min_points=10)]
    assert again == draws[3]


def test_a_source_without_airfoils_is_refused(tmp_path):
    (tmp_path / "notes.dat").write_text(FILES["notes.dat"])
    with pytest.raises(InvalidInput, match="no airfoil coordinate files found"):
        load_airfoils(tmp_path)
