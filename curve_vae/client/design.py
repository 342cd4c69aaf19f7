"""What /fit and /revolve answer, typed: least-squares B-splines of curves (`Fitted`), and the mesh file of a
surface of revolution (`Revolved`: its bytes, format and counts, `save` and `mesh`).

    fits = c.fit(np.c_[x, y], n_ctrl=8)
    fits.spline.control_points                    # (8, 2): the one curve's fit
    mesh = c.revolve(profile, segments=64)
    mesh.save("vase.obj")                         # atomic; refuses an existing file unless overwrite=True
"""

from __future__ import annotations

import os
import tempfile
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from curve_vae.client.results import ModelRef, Result, only

#: The media type of each mesh format the service writes (service/routes/design.py), and back.
MEDIA_TYPES = {"obj": "model/obj", "stl": "model/stl"}
FORMATS = {v: k for k, v in MEDIA_TYPES.items()}
STL_HEADER = 84  # 80 bytes of header and the triangle count
STL_TRIANGLE = np.dtype([("n", "<f4", 3), ("v", "<f4", (3, 3)), ("attr", "<u2")])


@dataclass(frozen=True)
class BSplineFit:
    """One curve's clamped cubic B-spline, fitted by least squares."""

    control_points: np.ndarray  # (n_ctrl, 2)
    knots: np.ndarray  # (n_ctrl + degree + 1,), clamped uniform on [0, 1]
    degree: int
    n_ctrl: int
    rms_error: float  # root mean squared distance of the points from the spline at their parameters
    max_error: float  # the largest such distance
    curve: np.ndarray | None = None  # (n_points, 2): the spline at n_points, when asked for

    @classmethod
    def from_json(cls, d: Mapping[str, Any]) -> BSplineFit:
        curve = d.get("curve")
        return cls(
            control_points=np.asarray(d["control_points"], np.float64).reshape(-1, 2),
            knots=np.asarray(d["knots"], np.float64),
            degree=int(d["degree"]),
            n_ctrl=int(d["n_ctrl"]),
            rms_error=float(d["rms_error"]),
            max_error=float(d["max_error"]),
            curve=None if curve is None else np.asarray(curve, np.float64).reshape(-1, 2),
        )

    def json(self) -> dict[str, Any]:
        """As the service sends it (and `curve-vae fit` writes it)."""
        out: dict[str, Any] = {
            "control_points": self.control_points.tolist(),
            "knots": self.knots.tolist(),
            "degree": self.degree,
            "n_ctrl": self.n_ctrl,
            "rms_error": self.rms_error,
            "max_error": self.max_error,
        }
        if self.curve is not None:
            out["curve"] = self.curve.tolist()
        return out


@dataclass(frozen=True)
class Fitted(Result):
    """One fit per input curve, in order."""

    fits: list[BSplineFit]

    @property
    def spline(self) -> BSplineFit:
        """The fit of a one-curve request; ValueError where there are more or none."""
        return only(self.fits, "spline", "fits")

    def json(self) -> dict[str, Any]:
        """The /fit body: {"fits": [...]}."""
        return {"fits": [f.json() for f in self.fits]}


@dataclass(frozen=True)
class Revolved(Result):
    """A surface of revolution as the mesh file the service wrote: `data` (OBJ text or binary STL), its `format`
    ("obj" or "stl") and `media_type`, and the counts and closedness the service sent with it (None where absent)."""

    data: bytes
    format: str
    n_vertices: int | None = None
    n_faces: int | None = None  # triangles
    closed: bool | None = None  # every edge joins two triangles: a watertight surface

    @classmethod
    def from_answer(cls, model: ModelRef, data: bytes, headers: Mapping[str, str], asked: str) -> Revolved:
        """From the answer's body and headers; `asked`: the format requested, where the answer names none."""
        media = headers.get("content-type", "").split(";")[0].strip().lower()
        closed = headers.get("x-mesh-closed")
        return cls(
            model,
            data,
            FORMATS.get(media, asked),
            _count(headers.get("x-mesh-vertices")),
            _count(headers.get("x-mesh-faces")),
            None if closed is None else closed.strip().lower() == "true",
        )

    @property
    def media_type(self) -> str:
        return MEDIA_TYPES.get(self.format, "application/octet-stream")

    def __bytes__(self) -> bytes:
        return self.data

    def save(self, path: str | os.PathLike[str], *, overwrite: bool = False) -> Path:
        """Write the file to `path`, atomically (a reader never sees half of it); an existing file is refused
        (FileExistsError) unless `overwrite`. Returns the path."""
        path = Path(path)
        if not overwrite and path.exists():
            raise _exists(path)
        fd, name = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
        tmp = Path(name)
        try:
            with os.fdopen(fd, "wb") as f:
                f.write(self.data)
            os.chmod(tmp, 0o644)
            if overwrite:
                os.replace(tmp, path)
            else:
                _place_new(tmp, path)
        finally:
            tmp.unlink(missing_ok=True)
        return path

    def mesh(self) -> tuple[np.ndarray, np.ndarray]:
        """The mesh as arrays: vertices (V, 3) float64 and triangles (F, 3) int64, 0-based, counter-clockwise seen
        from outside. STL stores each triangle's corners apart: equal corners are made one vertex again."""
        if self.format == "stl":
            return _stl_mesh(self.data)
        return _obj_mesh(self.data)


def _count(value: str | None) -> int | None:
    try:
        return None if value is None else int(value)
    except ValueError:
        return None


def _exists(path: Path) -> FileExistsError:
    return FileExistsError(f"{path} exists and is left as it is: pass overwrite=True to replace it")


def _place_new(tmp: Path, path: Path) -> None:
    """Move `tmp` to `path` unless something is there by now: a hard link fails where `path` exists, so a file
    made since the check is never replaced; a file system without hard links gets a plain rename."""
    try:
        os.link(tmp, path)
    except FileExistsError:
        raise _exists(path) from None
    except OSError:
        os.replace(tmp, path)


def _obj_mesh(data: bytes) -> tuple[np.ndarray, np.ndarray]:
    vertices, faces = [], []
    for line in data.decode().splitlines():
        kind, _, rest = line.partition(" ")
        if kind == "v":
            vertices.append([float(x) for x in rest.split()[:3]])
        elif kind == "f":  # "f a b c" or "f a/t/n …": the vertex index leads each corner
            faces.append([int(c.split("/")[0]) - 1 for c in rest.split()[:3]])
    return np.array(vertices, np.float64).reshape(-1, 3), np.array(faces, np.int64).reshape(-1, 3)


def _stl_mesh(data: bytes) -> tuple[np.ndarray, np.ndarray]:
    count = int(np.frombuffer(data, "<u4", 1, 80)[0]) if len(data) >= STL_HEADER else 0
    if len(data) != STL_HEADER + count * STL_TRIANGLE.itemsize:
        raise ValueError(f"not a binary STL of {count} triangles: {len(data)} bytes")
    corners = np.frombuffer(data, STL_TRIANGLE, count, STL_HEADER)["v"].reshape(-1, 3).astype(np.float64)
    vertices, index = np.unique(corners, axis=0, return_inverse=True)
    return vertices, index.reshape(-1, 3).astype(np.int64)
