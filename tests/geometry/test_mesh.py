"""Surfaces of revolution: counts, watertightness, orientation, file formats."""

import numpy as np
import pytest

from curve_vae.geometry import revolve


def _half_circle(n=21):
    t = np.linspace(-np.pi / 2, np.pi / 2, n)
    p = np.stack([np.cos(t), np.sin(t)], axis=1)
    p[[0, -1], 0] = 0.0  # both ends exactly on the axis x = 0
    return p


def _signed_volume(mesh):
    tri = mesh.vertices[mesh.faces]
    return np.einsum("ij,ij->i", tri[:, 0], np.cross(tri[:, 1], tri[:, 2])).sum() / 6


@pytest.mark.parametrize("axis", ["x", "y"])
def test_closed_profile_gives_watertight_outward_mesh(axis):
    prof = _half_circle()
    if axis == "x":
        prof = prof[:, ::-1]  # the same sphere, revolved about the horizontal axis
    m = revolve(prof, segments=32, axis=axis, axis_position=0.0)
    assert m.vertices.shape == (19 * 32 + 2, 3)  # 19 rings + 2 poles
    assert m.faces.shape == (18 * 2 * 32 + 2 * 32, 3)  # 18 quad bands + 2 fans
    use = m.edge_use()
    assert set(use.values()) == {2}, "every edge shared by exactly two faces"
    assert len(m.vertices) - len(use) + len(m.faces) == 2  # Euler characteristic of a sphere
    assert _signed_volume(m) == pytest.approx(4 / 3 * np.pi, rel=0.02)  # outward: positive volume


def test_open_profile_has_rims_and_counts():
    prof = np.array([[2.0, 0], [3, 1], [2.5, 2], [1.5, 3]])  # a vase wall, touching nothing
    m = revolve(prof, segments=16, axis_position=0.0)
    assert m.vertices.shape == (4 * 16, 3)
    assert m.faces.shape == (3 * 2 * 16, 3)
    use = m.edge_use()
    assert sorted(set(use.values())) == [1, 2]
    assert sum(1 for c in use.values() if c == 1) == 2 * 16  # the two rims


def test_vase_with_closed_bottom():
    prof = np.array([[0.0, 0], [2, 0], [3, 1], [2.5, 2], [1.5, 3]])  # bottom centre on the axis
    m = revolve(prof, segments=12, axis_position=0.0)
    assert m.vertices.shape == (1 + 4 * 12, 3)
    assert sum(1 for c in m.edge_use().values() if c == 1) == 12  # only the top rim is open


def test_default_axis_and_crossing_profile():
    prof = np.array([[5.0, 0], [7, 1], [6, 2]])
    m = revolve(prof, segments=8)  # axis through the leftmost point: that point is a pole
    assert m.vertices.shape == (1 + 2 * 8, 3)
    with pytest.raises(ValueError, match="crosses the axis"):
        revolve(prof, axis_position=6.0)


def test_obj_and_stl():
    m = revolve(_half_circle(9), segments=8, axis_position=0.0)
    obj = m.to_obj(comment="test")
    lines = obj.splitlines()
    assert sum(line.startswith("v ") for line in lines) == len(m.vertices)
    assert sum(line.startswith("f ") for line in lines) == len(m.faces)
    stl = m.to_stl()
    assert len(stl) == 84 + 50 * len(m.faces)
    assert int.from_bytes(stl[80:84], "little") == len(m.faces)
