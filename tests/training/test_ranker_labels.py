"""training/ranker_labels.py: the reading ranker's labels against a real (untrained, committed) model: every search
candidate of every curve with its error, written in chunks and resumed; the user-like curves they are drawn on."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from curve_vae.training.ranker_labels import label_curves, user_curves


@pytest.fixture(scope="module")
def labels(closest_model_dir: Path, tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("labels")
    label_curves(closest_model_dir, out, curves=24, seed=5, chunk=8, say=lambda _: None)
    return out


def test_labels_hold_every_search_candidate_with_its_error(labels: Path):
    files = sorted(labels.glob("labels-5-*.npz"))
    assert [f.name for f in files] == [f"labels-5-{k:04d}.npz" for k in range(3)]
    with np.load(files[0]) as d:
        assert int(d["seed"]) == 5 and d["points"].shape[1:] == (161, 2)
        per_curve = np.bincount(d["curve"])
        assert len(per_curve) == 8 and np.all(per_curve >= 6)  # six poses, each as given (and natural readings)
        assert set(np.unique(d["pose"])) == set(range(6)) and np.all(d["error"] > 0)


def test_labelling_again_resumes_and_writes_only_what_is_missing(labels: Path, closest_model_dir: Path):
    before = {f.name: f.stat().st_mtime_ns for f in labels.glob("*.npz")}
    (labels / "labels-5-0001.npz").unlink()
    said: list[str] = []
    label_curves(closest_model_dir, labels, curves=24, seed=5, chunk=8, say=said.append)
    after = {f.name: f.stat().st_mtime_ns for f in labels.glob("*.npz")}
    assert set(after) == set(before) and len(said) == 1 and said[0].startswith("chunk 2/3")
    assert after["labels-5-0000.npz"] == before["labels-5-0000.npz"]


def test_user_curves_are_seeded_and_moved():
    a, b = user_curves(6, seed=3), user_curves(6, seed=3)
    assert all(np.array_equal(x, y) for x, y in zip(a, b)) and len({len(c) for c in a}) > 1


def test_user_curves_are_drawn_from_the_families_asked_for():
    def closed_share(curves: list[np.ndarray]) -> float:
        return float(np.mean([np.hypot(*(c[-1] - c[0])) < 1e-6 * np.ptp(c, axis=0).max() for c in curves]))

    # airfoils (when their wheel is there) are drawn beside any family, some of them closed at the trailing edge
    assert closed_share(user_curves(40, seed=4, families=["closed"])) >= 0.7
    assert closed_share(user_curves(40, seed=4)) <= 0.3


def test_a_spent_time_budget_stops_at_a_chunks_start_and_returns_the_chunks_written(
    labels: Path, tmp_path: Path, closest_model_dir: Path
):
    out = tmp_path / "labels"
    out.mkdir()
    (out / "labels-5-0000.npz").write_bytes((labels / "labels-5-0000.npz").read_bytes())  # chunk 1 of 3 done
    said: list[str] = []
    files = label_curves(closest_model_dir, out, curves=24, seed=5, chunk=8, time_budget=1e-9, say=said.append)
    assert files == [out / "labels-5-0000.npz"] and sorted(out.iterdir()) == files  # nothing more written
    assert len(said) == 1 and said[0].startswith("time budget spent: 1 of ") and said[0].endswith("carry on")


def test_the_time_budget_message_counts_the_runs_chunks(labels: Path, tmp_path: Path, closest_model_dir: Path):
    out = tmp_path / "labels"
    out.mkdir()
    (out / "labels-5-0000.npz").write_bytes((labels / "labels-5-0000.npz").read_bytes())
    said: list[str] = []
    label_curves(closest_model_dir, out, curves=24, seed=5, chunk=8, time_budget=1e-9, say=said.append)
    assert said == ["time budget spent: 1 of 3 chunks; run again to carry on"]
