"""Surfaces of revolution (paper Fig. 12: a vase from a profile curve) and mesh file formats."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from curve_vae.errors import InvalidInput


@dataclass(frozen=True)
class Mesh:
    vertices: np.ndarray  # (V, 3) float64
    faces: np.ndarray  # (F, 3) int64, counter-clockwise seen from outside

    def to_obj(self, *, comment: str = "") -> str:
        """Wavefront OBJ text (1-based indices)."""
        head = [f"# {line}" for line in comment.splitlines()] if comment else []
        v = "\n".join(f"v {x:.6g} {y:.6g} {z:.6g}" for x, y, z in self.vertices)
        f = "\n".join(f"f {a + 1} {b + 1} {c + 1}" for a, b, c in self.faces)
        return "\n".join([*head, v, f]) + "\n"

    def to_stl(self, *, header: bytes = b"curve-vae surface of revolution") -> bytes:
        """Binary STL: 80-byte header, triangle count, 50 bytes per triangle."""
        tri = self.vertices[self.faces]  # (F, 3, 3)
        n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
        norm = np.linalg.norm(n, axis=1, keepdims=True)
        n = np.divide(n, norm, out=np.zeros_like(n), where=norm > 0)
        rec = np.zeros(len(tri), dtype=[("n", "<f4", 3), ("v", "<f4", (3, 3)), ("attr", "<u2")])
        rec["n"], rec["v"] = n, tri
        return header[:80].ljust(80, b"\0") + np.uint32(len(tri)).tobytes() + rec.tobytes()

    def edge_use(self) -> dict[tuple[int, int], int]:
        """How many faces use each undirected edge: 2 everywhere on a closed surface."""
        e = np.sort(self.faces[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2), axis=1)
        uniq, counts = np.unique(e, axis=0, return_counts=True)
        return {(int(a), int(b)): int(c) for (a, b), c in zip(uniq, counts)}


def revolve(
    profile: np.ndarray,
    *,
    segments: int = 64,
    axis: str = "y",
    axis_position: float | None = None,
    pole_tolerance: float = 1e-6,
) -> Mesh:
    """Revolve a 2D profile (n, 2) about a line of its plane into a triangle mesh.

    axis "y": the vertical line x = axis_position; "x": the horizontal line y = axis_position.
    By default the axis passes through the profile's extreme point on the near side (the
    smallest coordinate across the axis), so the whole profile lies on one side of it.
    Profile points within `pole_tolerance` (relative to the profile's size) of the axis
    become single pole vertices: a profile whose two ends touch the axis gives a closed,
    watertight surface; otherwise the surface is open at the rims of its end rings.
    """
    p = np.asarray(profile, dtype=np.float64)
    if p.ndim != 2 or p.shape[1] != 2 or len(p) < 2:
        raise InvalidInput(f"profile must have shape (n ≥ 2, 2), got {p.shape}")
    if segments < 3:
        raise InvalidInput(f"segments must be ≥ 3, got {segments}")
    if axis not in ("x", "y"):
        raise InvalidInput(f"axis must be 'x' or 'y', got {axis!r}")
    pos, r, h, pole = _about_axis(p, axis, axis_position, pole_tolerance)
    local, index = _rings(r, h, pole, segments)
    faces = _outwards(local, _bands(index, pole, segments))
    return Mesh(vertices=_world(local, axis, pos), faces=faces)


def _about_axis(
    p: np.ndarray, axis: str, axis_position: float | None, pole_tolerance: float
) -> tuple[float, np.ndarray, np.ndarray, np.ndarray]:
    """The axis position, and per profile point its distance from the axis, its height along it and whether it
    is a pole (on the axis); a profile with points on both sides of the axis is refused."""
    across, along = (0, 1) if axis == "y" else (1, 0)
    pos = float(p[:, across].min()) if axis_position is None else float(axis_position)
    r = p[:, across] - pos
    size = float(np.ptp(p, axis=0).max()) or 1.0
    if (r < -pole_tolerance * size).any() and (r > pole_tolerance * size).any():
        i = int(np.argmin(r) if r.min() < 0 else 0)
        raise InvalidInput(
            f"profile crosses the axis (point {i} lies on the other side); move the axis or split the profile"
        )
    r = np.abs(r)
    return pos, r, p[:, along], r <= pole_tolerance * size


def _rings(r: np.ndarray, h: np.ndarray, pole: np.ndarray, segments: int) -> tuple[np.ndarray, list[np.ndarray]]:
    """The vertices (radial, along-axis, tangential; the axis through the origin) of each profile point's ring
    (one vertex for a pole), and per profile point its ring's vertex ids."""
    theta = np.linspace(0.0, 2 * np.pi, segments, endpoint=False)
    verts: list[np.ndarray] = []
    index: list[np.ndarray] = []
    n = 0
    for ri, hi, is_pole in zip(r, h, pole):
        if is_pole:
            ring = np.array([[0.0, hi, 0.0]])
        else:
            ring = np.stack([ri * np.cos(theta), np.full(segments, hi), ri * np.sin(theta)], axis=1)
        verts.append(ring)
        index.append(np.arange(n, n + len(ring)))
        n += len(ring)
    return np.concatenate(verts), index


def _bands(index: list[np.ndarray], pole: np.ndarray, segments: int) -> np.ndarray:
    """The triangles between consecutive rings: a fan to a pole, two triangles a segment between two rings."""
    faces: list[np.ndarray] = []
    nxt = np.roll(np.arange(segments), -1)
    for a, b, pa, pb in zip(index[:-1], index[1:], pole[:-1], pole[1:]):
        if pa and pb:
            continue  # a stretch along the axis encloses no surface
        if pa:
            faces.append(np.stack([np.full(segments, a[0]), b[nxt], b], axis=1))
        elif pb:
            faces.append(np.stack([a, a[nxt], np.full(segments, b[0])], axis=1))
        else:
            faces.append(np.stack([a, a[nxt], b[nxt]], axis=1))
            faces.append(np.stack([a, b[nxt], b], axis=1))
    if not faces:
        raise InvalidInput("the profile lies on the axis: nothing to revolve")
    return np.concatenate(faces).astype(np.int64)


def _outwards(local: np.ndarray, f: np.ndarray) -> np.ndarray:
    """The faces oriented outwards: seen from the axis, every band's normal points away from it; the signed
    volume swept towards the axis is then positive (closed or open surface alike)."""
    tri = local[f]
    if np.einsum("ij,ij->i", tri[:, 0], np.cross(tri[:, 1], tri[:, 2])).sum() < 0:
        return f[:, ::-1]
    return f


def _world(local: np.ndarray, axis: str, pos: float) -> np.ndarray:
    """World coordinates: the revolution axis is the plane's y (or x) axis at the caller's position."""
    if axis == "y":
        return local + np.array([pos, 0.0, 0.0])
    return local[:, [1, 0, 2]] * np.array([1.0, 1.0, -1.0]) + np.array([0.0, pos, 0.0])  # a rotation
