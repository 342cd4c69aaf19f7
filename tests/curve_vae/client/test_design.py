"""curve_vae.client.design: a revolved mesh file saved atomically and never over an existing file unless asked, and
read back into the arrays of the mesh it was written from (OBJ and binary STL, as the service writes them)."""

from __future__ import annotations

import numpy as np
import pytest

from curve_vae.client.design import Revolved
from curve_vae.client.results import ModelRef
from curve_vae.geometry import revolve
from curve_vae.inference.results import mesh_file

MODEL = ModelRef("m", "1", "0.15.0", {})
PROFILE = np.array([[0, 0], [3, 0], [4, 1], [3, 3], [0, 5]], np.float64)


def _revolved(fmt: str, segments: int = 12) -> tuple[Revolved, object]:
    mesh = revolve(PROFILE, segments=segments)
    data = mesh_file(mesh, points=len(PROFILE), segments=segments, axis="y", fmt=fmt)
    return Revolved(MODEL, data, fmt, len(mesh.vertices), len(mesh.faces), True), mesh


def test_an_obj_file_reads_back_as_its_mesh():
    got, mesh = _revolved("obj")
    vertices, faces = got.mesh()
    assert vertices.shape == mesh.vertices.shape and faces.dtype == np.int64
    np.testing.assert_allclose(vertices, mesh.vertices, atol=1e-5)  # OBJ writes 6 significant digits
    np.testing.assert_array_equal(faces, mesh.faces)


def test_an_stl_file_reads_back_as_the_same_triangles():
    got, mesh = _revolved("stl")
    vertices, faces = got.mesh()
    assert len(faces) == got.n_faces and len(vertices) == got.n_vertices  # shared corners made one vertex again
    np.testing.assert_allclose(vertices[faces], mesh.vertices[mesh.faces], atol=1e-5)  # float32 in the file


def test_a_truncated_stl_is_an_error_naming_its_size():
    got, _ = _revolved("stl")
    with pytest.raises(ValueError, match=f"not a binary STL of {got.n_faces} triangles"):
        Revolved(MODEL, got.data[:-10], "stl").mesh()


def test_save_writes_the_file_and_leaves_nothing_else(tmp_path):
    got, _ = _revolved("obj")
    path = got.save(tmp_path / "vase.obj")
    assert path.read_bytes() == got.data and [p.name for p in tmp_path.iterdir()] == ["vase.obj"]


def test_save_refuses_an_existing_file_unless_asked(tmp_path):
    got, _ = _revolved("stl")
    path = tmp_path / "vase.stl"
    path.write_bytes(b"mine")
    with pytest.raises(FileExistsError, match="exists and is left as it is: pass overwrite=True"):
        got.save(path)
    assert path.read_bytes() == b"mine" and [p.name for p in tmp_path.iterdir()] == ["vase.stl"]
    got.save(path, overwrite=True)
    assert path.read_bytes() == got.data and [p.name for p in tmp_path.iterdir()] == ["vase.stl"]
