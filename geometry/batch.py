"""A batch of curves of any lengths as arrays: their canonical frames, and their points mapped into and out of the
model plane, for all curves at once.

A request's curves have their own lengths, so a batch is held "ragged": every point of every curve in one array
(N, 2), `lengths` (B,) saying how many belong to each curve, in order. Frames are per curve, applied to every point
through its owner's row (`FrameRows`). Curves of one length are stacked (k, n, 2) where a computation runs along a
curve (turning, centroids, bounding boxes): `canonical_frames` groups them so.

The per-curve functions of frame.py say what each step means; these give the same answers (to rounding) for a whole
batch in a few array operations, which is what the service's hot path runs (nothing per point or per curve in
Python).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import TypeVar

import numpy as np

from curve_vae.geometry.frame import (
    CLOSED,
    MODEL_CENTER,
    POSE_CHORDS,
    Frame,
    pose_candidates,
    posed_frame,
    resample,
)

T = TypeVar("T")


@dataclass(frozen=True)
class Ragged:
    """Curves of any lengths: their points end to end (N, 2) and each curve's point count (B,)."""

    points: np.ndarray
    lengths: np.ndarray

    @classmethod
    def of(cls, curves: Sequence[np.ndarray]) -> Ragged:
        lengths = np.array([len(c) for c in curves], np.int64)
        flat = np.concatenate([np.asarray(c, np.float64) for c in curves]) if len(curves) else np.zeros((0, 2))
        return cls(flat, lengths)

    @property
    def starts(self) -> np.ndarray:
        return np.concatenate([[0], np.cumsum(self.lengths)[:-1]]).astype(np.int64)

    @property
    def owner(self) -> np.ndarray:
        """(N,) the curve each point belongs to."""
        return np.repeat(np.arange(len(self.lengths)), self.lengths)

    def split(self, flat: np.ndarray) -> list[np.ndarray]:
        """Per-point values (N, …) back into one array per curve (views)."""
        return np.split(flat, np.cumsum(self.lengths)[:-1]) if len(self.lengths) else []

    def reversed_where(self, flip: np.ndarray) -> np.ndarray:
        """(N,) the index each point takes its value from when the curves where `flip` (B,) is true are listed end
        to end the other way round."""
        i = np.arange(len(self.points))
        own = self.owner
        first, count = self.starts[own], self.lengths[own]
        return np.where(flip[own], 2 * first + count - 1 - i, i)


@dataclass(frozen=True)
class FrameRows:
    """Frames (B of them) as arrays: centres (B, 2), sizes (B,), pose maps (B, 2, 2) (row vectors: p @ M), and
    which reverse the point order (B,)."""

    center: np.ndarray
    size: np.ndarray
    linear: np.ndarray
    reverse: np.ndarray

    @classmethod
    def of(cls, frames: Sequence[Frame]) -> FrameRows:
        return cls(
            np.array([f.center for f in frames], np.float64).reshape(-1, 2),
            np.array([f.size for f in frames], np.float64),
            pose_linears(
                np.array([f.rotation for f in frames], np.float64), np.array([f.mirror for f in frames], bool)
            ).reshape(-1, 2, 2),
            np.array([f.reverse for f in frames], bool),
        )

    def to_model(self, curves: Ragged, model_size: float) -> np.ndarray:
        """`Frame.to_model` of every curve (N, 2): each point through its own curve's frame, in the model's order."""
        own = curves.owner
        p = ((curves.points - self.center[own])[:, None, :] @ self.linear[own])[:, 0]  # each point times its M
        p = p * (model_size / self.size)[own, None] + np.asarray(MODEL_CENTER)
        return p[curves.reversed_where(self.reverse)]

    def to_model_rows(self, rows: np.ndarray, model_size: float) -> np.ndarray:
        """`Frame.to_model` of curves of one length (B, n, 2), each through its own frame, in the model's order."""
        d = rows - self.center[:, None]
        p = d @ self.linear  # each curve times its M
        p = p * (model_size / self.size)[:, None, None] + np.asarray(MODEL_CENTER)
        p[self.reverse] = p[self.reverse, ::-1]
        return p

    def from_model(self, curves: Ragged, model_size: float) -> np.ndarray:
        """`Frame.from_model` of every curve (N, 2): model-plane points back to their curves' frames and order."""
        own = curves.owner
        p = (curves.points - np.asarray(MODEL_CENTER)) * (self.size / model_size)[own, None]
        p = (self.linear[own] @ p[:, :, None])[:, :, 0] + self.center[own]  # times Mᵀ: the inverse
        return p[curves.reversed_where(self.reverse)]


# ----------------------------------------------------------------------------------------------- canonical frames


def canonical_frames(curves: Sequence[np.ndarray]) -> list[Frame]:
    """`frame.canonical_frame` of every curve, computed for the curves of each length together. Raises ValueError
    naming the first curve whose points all coincide."""
    return _by_length(curves, _canonical_same_length)


def _by_length(curves: Sequence[np.ndarray], per_length: Callable[[np.ndarray], list[T]]) -> list[T]:
    """`per_length` of the curves of each length stacked (k, n, 2), its answers back in the curves' order."""
    out: dict[int, T] = {}
    lengths = np.array([len(c) for c in curves])
    for n in np.unique(lengths):
        idx: list[int] = np.flatnonzero(lengths == n).tolist()
        out.update(zip(idx, per_length(np.stack([np.asarray(curves[i], np.float64) for i in idx]))))
    return [out[i] for i in range(len(curves))]


def arc_grids(curves: Sequence[np.ndarray], n_points: int, *, upright: bool = False) -> np.ndarray:
    """(k, n_points, 2): each curve at `n_points` evenly spaced along its length (`frame.resample` by arc length),
    the curves of each length at once; upright: a curve that turns clockwise overall (`frame.turns_clockwise`) is
    mirrored in x first. Each curve needs two distinct points."""

    def grids(pts: np.ndarray) -> list[np.ndarray]:
        s = _arc_lengths(pts)
        at = np.linspace(0.0, 1.0, n_points)[None, :] * s[:, -1:]  # (k, n_points) lengths to reach
        # the segment each falls in: the last point not beyond it, one row at a time (np.searchsorted is 1-D)
        seg = np.stack([np.searchsorted(row, a, side="right") - 1 for row, a in zip(s, at)])
        seg = np.clip(seg, 0, pts.shape[1] - 2)
        lo, hi = np.take_along_axis(s, seg, 1), np.take_along_axis(s, seg + 1, 1)
        w = np.where(hi > lo, (at - lo) / np.where(hi > lo, hi - lo, 1.0), 0.0)[..., None]
        a, b = np.take_along_axis(pts, seg[..., None], 1), np.take_along_axis(pts, seg[..., None] + 1, 1)
        out = a + (b - a) * w
        if upright:
            out[turns_clockwise_of(pts), :, 0] *= -1.0
        return list(out)

    rows: list[np.ndarray] = _by_length(curves, grids)
    return np.stack(rows) if rows else np.zeros((0, n_points, 2))


def arc_fractions_of(curves: Sequence[np.ndarray]) -> list[np.ndarray]:
    """`frame.arc_fractions` of every curve, the curves of each length at once."""

    def fractions(pts: np.ndarray) -> list[np.ndarray]:
        s = _arc_lengths(pts)
        return list(s / s[:, -1:])

    return _by_length(curves, fractions)


def _arc_lengths(pts: np.ndarray) -> np.ndarray:
    """(k, n): the arc length from each curve's first point to each of its points (frame.cumulative_length)."""
    seg = np.linalg.norm(np.diff(pts, axis=1), axis=2)
    return np.concatenate([np.zeros((len(pts), 1)), np.cumsum(seg, axis=1)], axis=1)


def _canonical_same_length(pts: np.ndarray) -> list[Frame]:
    """Canonical frames of curves of one length (k, n, 2); see frame.canonical_frame for what each step means."""
    extent = np.ptp(pts, axis=1).max(axis=1)  # (k,)
    if not (extent > 0).all():
        raise ValueError("all points coincide: a curve needs at least 2 distinct points")
    mirror = turns_clockwise_of(pts)
    flip = np.stack([np.where(mirror, -1.0, 1.0), np.ones(len(pts))], axis=-1)  # (k, 2)
    centroid = arc_centroids(pts)  # (k, 2): a wire's centroid moves with every linear map of it
    heading = chord_headings(pts * flip[:, None, :], centroid * flip)
    target = POSE_CHORDS[0]
    turn = np.angle(np.exp(1j * (target - heading)))
    drawn = pose_linears(turn, mirror)  # (k, 2, 2)
    # the other candidate: reflected across the chord's normal and reversed (frame.pose_frames' `flips`)
    normal = np.array([np.cos(target), np.sin(target)])
    c, s = np.cos(turn), np.sin(turn)
    rot = np.stack([np.stack([c, -s], -1), np.stack([s, c], -1)], -2)  # (k, 2, 2) column-vector rotations
    a = (np.eye(2) - 2 * np.outer(normal, normal)) @ rot @ np.diag([-1.0, 1.0])
    turn_flipped = np.arctan2(a[:, 1, 0], a[:, 0, 0])
    flipped = pose_linears(turn_flipped, ~mirror)
    posed = pts @ drawn  # chord along −y (a translation changes no statistic below)
    centroid = (centroid[:, None] @ drawn)[:, 0]
    offset = (posed[:, 0, 1] + posed[:, -1, 1]) / 2 - centroid[:, 1]
    box_drawn = _box(pts, drawn)
    level = np.abs(offset) <= 1e-9 * box_drawn[1]
    if level.any():  # a loop's centroid lies on its chord's normal: the product moment decides
        seg = np.linalg.norm(np.diff(posed, axis=1), axis=2)
        rel = (posed[:, 1:] + posed[:, :-1]) / 2 - centroid[:, None, :]
        offset = np.where(level, -(seg * rel[..., 0] * rel[..., 1]).sum(axis=1), offset)
    keep = offset >= 0
    box_flipped = _box(pts, flipped)
    frames = []
    for i in range(len(pts)):
        (center, size), turned, mir, rev = (
            ((box_drawn[0][i], box_drawn[1][i]), turn[i], mirror[i], False)
            if keep[i]
            else ((box_flipped[0][i], box_flipped[1][i]), turn_flipped[i], not mirror[i], True)
        )
        frames.append(Frame((float(center[0]), float(center[1])), float(size), float(turned), bool(mir), rev))
    return frames


def pose_frames_of(curves: Sequence[np.ndarray], *, chords: int = 3, flips: bool = True) -> list[list[Frame]]:
    """`frame.pose_frames` of every curve, computed for the curves of each length together. Raises ValueError naming
    the first curve whose points all coincide."""
    return _by_length(curves, lambda pts: _poses_same_length(pts, chords, flips))


def _poses_same_length(pts: np.ndarray, chords: int, flips: bool) -> list[list[Frame]]:
    """Pose frames of curves of one length (k, n, 2); see frame.pose_frames and frame.pose_candidates."""
    if not (np.ptp(pts, axis=1).max(axis=1) > 0).all():
        raise ValueError("all points coincide: a curve needs at least 2 distinct points")
    mirror = turns_clockwise_of(pts)
    flip = np.stack([np.where(mirror, -1.0, 1.0), np.ones(len(pts))], axis=-1)  # (k, 2)
    heading = chord_headings(pts * flip[:, None, :], arc_centroids(pts) * flip)
    poses: list[tuple[np.ndarray, np.ndarray, bool]] = []  # (rotation (k,), mirror (k,), reverse), in pose order
    for target in POSE_CHORDS[:chords]:
        turn = np.angle(np.exp(1j * (target - heading)))
        poses.append((turn, mirror, False))
        if flips:
            # reflected across the chord's normal after the turn and the mirror (frame.pose_candidates' S·R(turn)·M):
            # two reflections, whose axes lie at target + π/2 and (turn + π) / 2, make the turn 2·target − turn
            poses.append((np.angle(np.exp(1j * (2 * target - turn))), ~mirror, True))
    turns, mirrors, reverses = zip(*poses)
    turn, mir = np.stack(turns, axis=1), np.stack(mirrors, axis=1)  # (k, poses)
    linear = pose_linears(turn.ravel(), mir.ravel()).reshape(*turn.shape, 2, 2)
    q = pts[:, None] @ linear  # every pose's bounding box at once (frame.posed_frame); (k, poses, n, 2)
    lo, hi = q.min(axis=2), q.max(axis=2)
    center, size = (linear @ ((lo + hi) / 2)[..., None])[..., 0].tolist(), (hi - lo).max(axis=2).tolist()
    turn_, mir_ = turn.tolist(), mir.tolist()
    return [
        [
            Frame((center[i][p][0], center[i][p][1]), size[i][p], turn_[i][p], mir_[i][p], reverses[p])
            for p in range(len(reverses))
        ]
        for i in range(len(pts))
    ]


def pose_linears(rotation: np.ndarray, mirror: np.ndarray) -> np.ndarray:
    """The 2×2 map of each pose (k, 2, 2), row vectors (p @ M), mirror first: what a Frame's pose does to its points."""
    c, s = np.cos(rotation), np.sin(rotation)
    m = np.stack([np.stack([c, s], -1), np.stack([-s, c], -1)], -2)
    m[mirror] = np.array([[-1.0, 0.0], [0.0, 1.0]]) @ m[mirror]
    return m


def _box(pts: np.ndarray, linear: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """frame.posed_frame's centre (k, 2) and size (k,): the bounding box taken in the posed orientation."""
    q = pts @ linear
    lo, hi = q.min(axis=1), q.max(axis=1)
    return (linear @ ((lo + hi) / 2)[..., None])[..., 0], (hi - lo).max(axis=1)


def signed_turnings(pts: np.ndarray) -> np.ndarray:
    """Total signed turning of each polyline (k, n, 2) -> (k,), radians: positive where it turns counter-clockwise
    overall. A segment of zero length is skipped (the turn between the moving segments on either side of it counts
    once); a polyline with fewer than two moving segments turns 0."""
    d = np.diff(pts, axis=1)  # (k, n - 1, 2)
    moving = (d != 0).any(axis=2)
    if not moving.all():
        # each zero-length segment takes the last moving segment before it (or the first after it), so the repeats
        # add nothing
        j = np.arange(d.shape[1])
        last = np.maximum.accumulate(np.where(moving, j, -1), axis=1)
        first = np.argmax(moving, axis=1)
        d = np.take_along_axis(d, np.where(last < 0, first[:, None], last)[..., None], axis=1)
    cross = d[:, :-1, 0] * d[:, 1:, 1] - d[:, :-1, 1] * d[:, 1:, 0]
    dot = d[:, :-1, 0] * d[:, 1:, 0] + d[:, :-1, 1] * d[:, 1:, 1]
    turning = np.arctan2(cross, dot).sum(axis=1)
    return np.where(moving.sum(axis=1) >= 2, turning, 0.0)


def turns_clockwise_of(pts: np.ndarray) -> np.ndarray:
    """Whether each curve (k, n, 2) turns clockwise overall (k,), the side a posed curve is mirrored from: by its
    signed turning, or where that is zero to rounding (straight lines, S-bends) by the signed area it encloses with
    its chord. Both change sign with the point order and with a mirror image, and neither with a turn."""
    turning = signed_turnings(pts)
    clockwise = turning < 0
    level = np.abs(turning) <= 1e-9
    if level.any():  # straight lines, S-bends: the signed area the curve encloses with its chord
        x, y = pts[level, :, 0], pts[level, :, 1]
        clockwise[level] = (x * np.roll(y, -1, axis=1) - np.roll(x, -1, axis=1) * y).sum(axis=1) < 0
    return clockwise


def arc_centroids(pts: np.ndarray) -> np.ndarray:
    """Centre of mass of each polyline (k, n, 2) -> (k, 2) as a wire: its segments' midpoints weighted by their
    lengths, so it does not depend on how the points are spaced along it (the points' mean where it has no length)."""
    seg = np.linalg.norm(np.diff(pts, axis=1), axis=2)
    total = seg.sum(axis=1)
    mid = (pts[:, 1:] + pts[:, :-1]) / 2
    wire = (mid * seg[..., None]).sum(axis=1) / np.where(total > 0, total, 1.0)[:, None]
    return np.where((total > 0)[:, None], wire, pts.mean(axis=1))


def chord_headings(pts: np.ndarray, centroid: np.ndarray | None = None) -> np.ndarray:
    """Direction (radians) of each curve's chord (k, n, 2) -> (k,), first point -> last. For a closed or nearly closed
    loop (an airfoil: a chord shorter than CLOSED of the curve's extent) the direction its opening would have: a
    counter-clockwise loop that starts on its right has its chord pointing down, as the paper's curves do.
    `centroid`: their arc centroids, where known."""
    chord = pts[:, -1] - pts[:, 0]
    centroid = arc_centroids(pts) if centroid is None else centroid
    reach = 2 * np.linalg.norm(pts - centroid[:, None], axis=2).max(axis=1)  # the extent, however it is turned
    out = (pts[:, 0] + pts[:, -1]) / 2 - centroid  # alike for the loop listed either way, at any spacing
    return np.where(
        np.hypot(chord[:, 0], chord[:, 1]) >= CLOSED * reach,
        np.arctan2(chord[:, 1], chord[:, 0]),
        np.arctan2(out[:, 1], out[:, 0]) - np.pi / 2,
    )


# ----------------------------------------------------------------------------------------------- one pose for a set


def shared_pose_frames(curves: Sequence[np.ndarray], *, chords: int = 3, flips: bool = True) -> list[list[Frame]]:
    """`frame.pose_frames` for a set of curves that are mixed together (interpolated, augmented): the same candidate
    poses — one rotation, mirror image and point order each — for every curve of the set, so that the curves keep
    their turns relative to each other and in-betweens come back in the plane they were drawn in; each curve's frame
    still fits its own bounding box (centres and sizes blend).

    The curves are aligned one way first: a curve listed the other way round from the set's first curve (nearer it
    point for point reversed than as listed) is read reversed, so a curve and its reversal are read alike. The set
    is mirrored when its aligned curves turn clockwise overall (their signed turnings summed), and its chord
    direction is the mean of their unit chord directions; from there the candidates are pose_frames' own. Per curve:
    [candidate 0, candidate 1, …]; candidate k is one pose for the whole set.
    """
    pts = [np.asarray(c, np.float64) for c in curves]
    if not pts:
        return []
    for c in pts:
        if not np.ptp(c, axis=0).max() > 0:
            raise ValueError("all points coincide: a curve needs at least 2 distinct points")
    against = _against_first(pts)
    aligned = [c[::-1] if a else c for c, a in zip(pts, against)]
    turning = float(sum(signed_turnings(c[None])[0] for c in aligned))
    if abs(turning) > 1e-9:
        mirror = turning < 0
    else:
        mirror = sum(float(turns_clockwise_of(c[None])[0]) - 0.5 for c in aligned) > 0
    flip = np.array([-1.0, 1.0]) if mirror else np.ones(2)
    headings = np.array([chord_headings((c * flip)[None])[0] for c in aligned])
    heading = float(np.arctan2(np.sin(headings).sum(), np.cos(headings).sum()))
    poses = pose_candidates(heading, mirror, chords=chords, flips=flips)
    return [
        [posed_frame(c, turn, mirror=mir, reverse=rev != a) for turn, mir, rev in poses] for c, a in zip(pts, against)
    ]


#: A curve of a set is read reversed when, reversed, it lies within this share of its distance as listed from the
#: set's first curve (point for point, in their own boxes).
AGAINST = 0.5


def _against_first(curves: list[np.ndarray], samples: int = 32) -> list[bool]:
    """Which curves run the other way round from the first: those that, each in its own bounding box (centred, unit
    size) and at `samples` points evenly along its length, lie clearly nearer the first point for point when
    reversed than as listed (AGAINST: a curve and its reversal; two strokes of one shape drawn from opposite ends;
    not two different shapes whose ends lie close together, which stay as they were drawn)."""

    def shape(c: np.ndarray) -> np.ndarray:
        lo, hi = c.min(axis=0), c.max(axis=0)
        return resample((c - (lo + hi) / 2) / (hi - lo).max(), samples)

    first = shape(curves[0])
    out = []
    for c in curves:
        mine = shape(c)
        reversed_, listed = (np.linalg.norm(m - first, axis=1).sum() for m in (mine[::-1], mine))
        out.append(bool(reversed_ < AGAINST * listed))
    return out


def shared_canonical_frames(curves: Sequence[np.ndarray]) -> list[Frame]:
    """`frame.canonical_frame` for a set of curves mixed together: of the set's first two shared candidates (chord
    straight down; as drawn, or reversed and mirrored across the chord's normal), the one in which the curves'
    arc-length centroids lie towards their chords' ends on the whole (each curve's offset ÷ its size, summed; a curve
    alone gets its own canonical frame)."""
    if len(curves) <= 1:
        return canonical_frames(curves)
    candidates = shared_pose_frames(curves, chords=1)
    total = 0.0
    for c, (drawn, _) in zip(curves, candidates):
        posed = np.asarray(c, np.float64) @ drawn._linear()
        centroid = arc_centroids(posed[None])[0]
        total += ((posed[0, 1] + posed[-1, 1]) / 2 - centroid[1]) / drawn.size
    return [drawn if total >= 0 else flipped for drawn, flipped in candidates]
