"""curve_vae.client.writers: batches on disk (.npy, .npz, Parquet) that round-trip with their manifest, made again
from it by the server it names and refused by a server of another model; streamed chunks written whole, in order,
and a file of another kind or a manifest of another endpoint refused."""

from __future__ import annotations

import json

import httpx
import numpy as np
import pytest

from curve_vae.client import Client
from curve_vae.client.results import Augmented, ModelRef
from curve_vae.client.writers import manifest_path, read_batch, regenerate, write_augment, write_chunks
from curve_vae.errors import InvalidInput

C1 = [[0, 0], [1, 2], [2.5, 3.2], [4, 3.5], [5.5, 3], [7, 1.5], [8, 0]]
C2 = [[0, 0], [1.5, 0.5], [3, 2], [4, 4], [5, 6.5], [6.5, 8], [8, 8.5]]
C3 = [[0, 4], [2, 5], [4, 4], [6, 2], [8, 1], [10, 2], [12, 4]]


@pytest.mark.parametrize("suffix", [".parquet", ".npz", ".npy"])
def test_a_batch_file_round_trips_with_its_manifest(live_server, tmp_path, suffix):
    if suffix == ".parquet":
        pytest.importorskip("pyarrow")
    path = tmp_path / f"batch{suffix}"
    with Client(live_server.url) as c:
        m = write_augment(path, c, [C1, C2, C3], 50, seed=11, chunk=16, mode="triplet", n_points=24)
        want = c.augment([C1, C2, C3], 50, seed=11, mode="triplet", n_points=24).curves
        served = c.model_ref()
    got = read_batch(path)
    assert got.shape == (50, 24, 2) and got.dtype == np.float32
    np.testing.assert_allclose(got, want, atol=1e-5)
    saved = json.loads(manifest_path(path).read_text())
    assert saved == m and saved["seed"] == 11 and saved["shape"] == [50, 24, 2]
    assert saved["model"]["sha256"] == served.sha256 and saved["model"]["version"] == served.version
    assert saved["request"]["body"]["mode"] == "triplet"
    again = tmp_path / f"again{suffix}"
    regenerate(manifest_path(path), again)
    np.testing.assert_array_equal(read_batch(again), got)


def test_a_manifest_of_another_model_is_refused(live_server, tmp_path):
    path = tmp_path / "b.npz"
    with Client(live_server.url) as c:
        write_augment(path, c, [C1, C2], 8, seed=1)
    m = json.loads(manifest_path(path).read_text())
    m["model"]["sha256"]["decoder.onnx"] = "0" * 64
    manifest_path(path).write_text(json.dumps(m))
    with pytest.raises(ValueError, match="its curves would differ"):
        regenerate(manifest_path(path), tmp_path / "c.npz")


def _chunks(sizes: list[int], n_points: int = 6) -> list[Augmented]:
    """Chunks of a sequence as augment_chunks yields them: item i's points all i + 0.5."""
    model = ModelRef("m", "1", "0.15.0", {})
    out, start = [], 0
    for n in sizes:
        curves = np.repeat(np.arange(start, start + n, dtype=np.float32)[:, None, None] + 0.5, n_points, 1)
        out.append(Augmented(model, np.repeat(curves, 2, 2), offset=start))
        start += n
    return out


@pytest.mark.parametrize("suffix", [".npy", ".npz", ".parquet"])
def test_chunks_are_written_in_order_as_one_float32_array(tmp_path, suffix):
    path = tmp_path / f"b{suffix}"
    assert write_chunks(path, 9, iter(_chunks([4, 4, 1]))) == (9, 6, 2)
    got = read_batch(path)
    assert got.dtype == np.float32 and got.shape == (9, 6, 2)
    np.testing.assert_array_equal(got[:, 0, 0], np.arange(9) + 0.5)
    assert [p.name for p in tmp_path.iterdir()] == [path.name]  # written beside and renamed: nothing else left


def test_parquet_rows_carry_their_place_in_the_sequence(tmp_path):
    pq = pytest.importorskip("pyarrow.parquet")
    write_chunks(tmp_path / "b.parquet", 5, iter(_chunks([3, 2], n_points=4)))
    table = pq.read_table(str(tmp_path / "b.parquet"))
    assert table.column_names == ["index", "curve"] and table.column("index").to_pylist() == [0, 1, 2, 3, 4]
    assert table.column("curve").to_pylist()[3] == [[3.5, 3.5]] * 4


@pytest.mark.parametrize("name", ["b.json", "b.csv", "b.NPY"])
def test_another_kind_of_file_is_refused_before_anything_is_written(tmp_path, name):
    with pytest.raises(InvalidInput, match=rf"{name.replace('.', '[.]')}: write \.npy, \.npz or \.parquet"):
        write_chunks(tmp_path / name, 4, iter(_chunks([4])))
    assert list(tmp_path.iterdir()) == []


def test_chunks_short_of_the_count_leave_no_npy(tmp_path):
    with pytest.raises(InvalidInput, match="chunks gave 3 rows, the header promised 8"):
        write_chunks(tmp_path / "b.npy", 8, iter(_chunks([3])))
    assert list(tmp_path.iterdir()) == []


def test_a_manifest_sits_beside_its_file():
    assert manifest_path("out/b.parquet").as_posix() == "out/b.parquet.manifest.json"


def test_a_manifest_of_another_endpoint_is_not_made_again(tmp_path):
    m = {"request": {"endpoint": "/sample", "body": {"count": 3}}, "model": {"url": "http://127.0.0.1:9"}}
    (tmp_path / "s.npy.manifest.json").write_text(json.dumps(m))
    with pytest.raises(InvalidInput, match=r"s\.npy\.manifest\.json: made by /sample; only /augment batches"):
        regenerate(tmp_path / "s.npy.manifest.json", tmp_path / "again.npy")
    assert not (tmp_path / "again.npy").exists()


def test_one_seed_curve_is_refused_before_anything_is_asked_or_written(tmp_path):
    seen: list[str] = []
    transport = httpx.MockTransport(lambda r: seen.append(r.url.path) or httpx.Response(500))
    with Client("http://x", transport=transport) as c:
        with pytest.raises(InvalidInput, match="write_augment needs at least 2 curves, got one curve"):
            write_augment(tmp_path / "b.npy", c, np.array(C1), 8, seed=1)
    assert seen == [] and list(tmp_path.iterdir()) == []
