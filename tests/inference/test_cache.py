"""inference.prepared: curves read once are read from the cache, the same answer, bounded in bytes."""

from __future__ import annotations

import numpy as np

from curve_vae.inference.prepared import EncodingCache
from curve_vae.inference.reading import Reading
from curve_vae.inference.runtime import CurveRuntime
from tests.helpers import bspline_curves


def test_a_curve_read_again_comes_from_the_cache_with_the_same_answer(model_dir):
    rt = CurveRuntime.load(model_dir, providers="cpu", intra_op_threads=1)
    curves = list(bspline_curves(3, 90, seed=8) * 0.1 + 4)
    rows: list[int] = []
    encode = rt.graphs.encode
    rt.graphs.encode = lambda x: rows.append(len(x)) or encode(x)  # type: ignore[method-assign]
    first = rt.reconstruct(curves)
    encoded = sum(rows)
    again = rt.reconstruct(curves)
    assert sum(rows) == encoded  # nothing encoded the second time
    for a, b in zip(first.curves, again.curves):
        np.testing.assert_array_equal(a, b)
    np.testing.assert_array_equal(first.mse, again.mse)
    assert rt.cache is not None and rt.cache.hits == 3
    other = rt.reconstruct(curves, Reading(pose="as_is"))  # another reading of the same points: read afresh
    assert sum(rows) > encoded and not np.allclose(other.mse, first.mse)
    moved = rt.reconstruct([curves[0] + 1e-9])  # other bytes: read afresh
    assert rt.cache.misses == 3 + 3 + 1 and len(moved.curves) == 1


def test_the_cache_holds_at_most_its_bytes_least_recently_used_out_first(model_dir):
    rt = CurveRuntime.load(model_dir, providers="cpu", intra_op_threads=1, cache_bytes=0)
    prep = rt.prepare(list(bspline_curves(6, 161, seed=9)), Reading(pose="as_is", spacing="parameter"))
    size = prep.rows[0].nbytes()  # every row alike: one reading of curves of one length
    cache = EncodingCache(max_bytes=3 * size + size // 2)
    keys = [EncodingCache.key(c, "r") for c in prep.inputs]
    for k, row in zip(keys, prep.rows):
        cache.put(k, row)
    assert len(cache) == 3 and cache.size <= cache.max_bytes
    kept = cache.get(keys[5])
    assert cache.get(keys[0]) is None and kept is not None
    np.testing.assert_array_equal(kept.mean, prep.rows[5].mean)  # the same row (a copy of its own, see below)
    cache.get(keys[3])  # used: kept over the older 4
    cache.put(keys[0], prep.rows[0])
    assert cache.get(keys[3]) is not None and cache.get(keys[4]) is None
    assert EncodingCache(0).max_bytes == 0 and len(EncodingCache(0)) == 0


def test_interpolating_cached_curves_costs_one_decode_per_row(model_dir):
    """The page's slider: the same two curves posted again, one weight row: no encoding, one decoded row."""
    rt = CurveRuntime.load(model_dir, providers="cpu", intra_op_threads=1)
    curves = list(bspline_curves(2, 80, seed=10))
    rt.interpolate(curves, np.array([[0.5, 0.5]]))
    encoded, decoded = [], []
    encode, decode = rt.graphs.encode, rt.graphs.decode
    rt.graphs.encode = lambda x: encoded.append(len(x)) or encode(x)  # type: ignore[method-assign]
    rt.graphs.decode = lambda z: decoded.append(len(z)) or decode(z)  # type: ignore[method-assign]
    rt.interpolate(curves, np.array([[0.3, 0.7]]))
    assert encoded == [] and decoded == [1]


def test_a_kept_row_holds_its_own_bytes_not_the_batch_it_was_sliced_from():
    """The bytes the cache counts are the bytes it keeps: a row whose arrays are views into a request's batch
    would keep the whole batch alive (a soak of unseen curves grew 66 MiB a minute before this)."""
    import gc
    import weakref

    from curve_vae.inference.prepared import ReadCurve

    batch = np.ones((4096, 161, 2), np.float32)  # 5 MiB, as a request's candidates are
    latents = np.zeros((4096, 32), np.float32)
    row = ReadCurve(frame=None, model=batch[7], fraction=None, mean=latents[7], log_var=latents[8], decoded=batch[9])
    cache = EncodingCache(max_bytes=1 << 20)
    cache.put(b"k", row)
    alive = weakref.ref(batch)
    del batch, latents, row
    gc.collect()
    assert alive() is None  # only the row's own points stayed
    kept = cache.get(b"k")
    assert kept is not None and kept.model.flags.owndata and kept.decoded is not None and kept.decoded.flags.owndata
    np.testing.assert_array_equal(kept.model, np.ones((161, 2), np.float32))
