"""inference/weights.py: a learned part's weights file is read only when it names the kind of network asked for."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from curve_vae.errors import InvalidInput
from curve_vae.inference.weights import read_weights


def test_the_arrays_come_back_without_their_kind(tmp_path: Path):
    np.savez(tmp_path / "w.npz", kind="net-v1", a_w=np.arange(6.0).reshape(2, 3), dilations=np.array([1, 2]))
    got = read_weights(tmp_path / "w.npz", "net-v1", "a test net")
    assert set(got) == {"a_w", "dilations"}
    np.testing.assert_array_equal(got["a_w"], np.arange(6.0).reshape(2, 3))


@pytest.mark.parametrize(("saved", "found"), [({"kind": "net-v2"}, "'net-v2'"), ({}, "''")])
def test_another_kind_or_none_is_refused_by_name(tmp_path: Path, saved, found):
    np.savez(tmp_path / "w.npz", a_w=np.zeros(3), **saved)
    with pytest.raises(InvalidInput, match=f"w.npz: a test net of kind {found}; this runtime reads 'net-v1'"):
        read_weights(tmp_path / "w.npz", "net-v1", "a test net")
