"""Coordinate frames and resampling: how any curve is brought to the model and back.

The model works in the paper's 128×128 plane. A caller's curve may live anywhere at any
size and have any number of points; `fit_frame` finds the similarity (shift + uniform
scale) that maps its bounding box onto the model's, and `resample` moves it to the model's
point count by arc length. A frame may also carry a pose — a rotation, a mirror image and a
reversal of the point order — that brings the curve into the orientation the model was
trained on (`pose_frames`). All of it is exactly invertible up to float error.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from curve_vae.errors import InvalidInput

#: Centre of the model's plane (paper §3.1: a radius-64 circle in a 128×128 plane).
MODEL_CENTER = (64.0, 64.0)
#: The larger bounding-box side of a curve in the model plane: the paper's curves' median. Training poses its curves
#: at this size and export records it in the manifest (`model_size`), which is what serving reads.
MODEL_SIZE = 92.6


@dataclass(frozen=True)
class Frame:
    """Where a curve lives and how it is turned: the centre of its bounding box and its larger side; and the pose
    that takes it to the model — mirror x about the centre (`mirror`), then turn by `rotation` radians
    counter-clockwise, with the point order reversed (`reverse`). The default pose is the identity."""

    center: tuple[float, float]
    size: float
    rotation: float = 0.0
    mirror: bool = False
    reverse: bool = False

    @property
    def posed(self) -> bool:
        return bool(self.rotation or self.mirror or self.reverse)

    def _linear(self) -> np.ndarray:
        """The 2×2 map of the pose (row vectors: p @ M), mirror first: geometry.batch.pose_linears of one."""
        from curve_vae.geometry.batch import pose_linears  # batch builds on Frame

        return pose_linears(np.array([self.rotation], np.float64), np.array([self.mirror], bool))[0]

    def to_model(self, pts: np.ndarray, model_size: float) -> np.ndarray:
        """Map points of this frame into the model plane, bounding box size `model_size`."""
        p = np.asarray(pts, np.float64) - np.asarray(self.center)
        if self.posed:
            p = p @ self._linear()
            p = p[::-1] if self.reverse else p
        return p * (model_size / self.size) + np.asarray(MODEL_CENTER)

    def from_model(self, pts: np.ndarray, model_size: float) -> np.ndarray:
        """Inverse of `to_model` (points in the model's order come back in the caller's)."""
        p = (np.asarray(pts, np.float64) - np.asarray(MODEL_CENTER)) * (self.size / model_size)
        if self.posed:
            p = p @ self._linear().T  # orthogonal: the inverse is the transpose
            p = p[::-1] if self.reverse else p
        return p + np.asarray(self.center)

    def to_caller_params(self, u: np.ndarray) -> np.ndarray:
        """Parameters of points in the model's order -> the same points' parameters in the caller's order."""
        u = np.asarray(u, np.float64)
        return (1.0 - u)[::-1] if self.reverse else u


def fit_frame(points: np.ndarray) -> Frame:
    """Frame of one curve (n, 2). Raises ValueError when all points coincide."""
    pts = np.asarray(points, dtype=np.float64)
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    size = float((hi - lo).max())
    if not size > 0:
        raise InvalidInput("all points coincide: a curve needs at least 2 distinct points")
    center = (lo + hi) / 2
    return Frame(center=(float(center[0]), float(center[1])), size=size)


def blend_frames(frames: list[Frame], weights: np.ndarray) -> list[Frame]:
    """Affine blend of frames, one per weight row: the frame an interpolant is returned in.

    weights: (rows, len(frames)), each row summing to 1. Centres and sizes blend linearly;
    mirror and order, which do not blend, come from the heaviest frame of each row, and
    rotations blend as weighted unit vectors (the shorter way round) over the frames that
    mirror as it does: a turn means another thing in a mirrored frame. A curve and its own
    reversal get frames that differ in order alone, so every blend of the two is the curve.
    """
    centers = np.array([f.center for f in frames])  # (k, 2)
    sizes = np.array([f.size for f in frames])  # (k,)
    turns = np.array([[np.cos(f.rotation), np.sin(f.rotation)] for f in frames])  # (k, 2)
    w = np.asarray(weights, dtype=np.float64)
    mirrors = np.array([f.mirror for f in frames])
    out_c, out_s = w @ centers, w @ sizes
    # An extrapolating row could drive the size to zero or below; keep the frame invertible.
    out_s = np.maximum(out_s, 1e-12 * sizes.max())
    out = []
    for row, c, s in zip(w, out_c, out_s):
        lead = frames[int(np.argmax(row))]
        t = (row * (mirrors == lead.mirror)) @ turns
        rotation = float(np.arctan2(t[1], t[0])) if np.hypot(*t) > 1e-12 else lead.rotation
        out.append(Frame((float(c[0]), float(c[1])), float(s), rotation, lead.mirror, lead.reverse))
    return out


#: Directions (radians) the chord of a posed curve is turned to: the paper's generator draws curves whose chord
#: (first point -> last) points into the lower half-plane, about straight down, and which turn counter-clockwise.
POSE_CHORDS = (-np.pi / 2, -np.pi / 4, -3 * np.pi / 4)
#: A chord shorter than this share of the curve's extent (twice its furthest point from its centroid) marks a
#: closed-looking curve (see chord_heading).
CLOSED = 0.05


def signed_turning(points: np.ndarray) -> float:
    """Total signed turning of a polyline (n, 2), radians: a batch of one of geometry.batch.signed_turnings."""
    from curve_vae.geometry.batch import signed_turnings  # batch builds on this module

    return float(signed_turnings(np.asarray(points, np.float64)[None])[0])


def turns_clockwise(points: np.ndarray) -> bool:
    """Whether a curve turns clockwise overall: a batch of one of geometry.batch.turns_clockwise_of."""
    from curve_vae.geometry.batch import turns_clockwise_of

    return bool(turns_clockwise_of(np.asarray(points, np.float64)[None])[0])


def chord_heading(points: np.ndarray) -> float:
    """Direction (radians) of a curve's chord, or a loop's opening: a batch of one of geometry.batch.chord_headings."""
    from curve_vae.geometry.batch import chord_headings

    return float(chord_headings(np.asarray(points, np.float64)[None])[0])


def arc_centroid(points: np.ndarray) -> np.ndarray:
    """Centre of mass (2,) of a polyline as a wire: a batch of one of geometry.batch.arc_centroids."""
    from curve_vae.geometry.batch import arc_centroids

    return arc_centroids(np.asarray(points, np.float64)[None])[0]


def pose_frames(points: np.ndarray, *, chords: int = 3, flips: bool = True) -> list[Frame]:
    """Candidate frames that bring a curve into the model's pose, best guess first: a batch of one of
    geometry.batch.pose_frames_of.

    Each mirrors a clockwise curve, then turns its chord to one of the first `chords` of
    `POSE_CHORDS`. With `flips`, each also comes reversed and mirrored across its chord's
    normal: the same two moves leave chord and turning as they were, so only with both
    does a curve and its reversal, mirror image or rotation get the same set of candidates.
    Raises ValueError where all points coincide.
    """
    from curve_vae.geometry.batch import pose_frames_of

    return pose_frames_of([np.asarray(points, np.float64)], chords=chords, flips=flips)[0]


def pose_candidates(
    heading: float, mirror: bool, *, chords: int = 3, flips: bool = True
) -> list[tuple[float, bool, bool]]:
    """The poses (rotation, mirror, reverse) `pose_frames` tries for a curve whose chord, mirrored as `mirror`
    says, points at `heading` (radians): its chord turned to each of the first `chords` POSE_CHORDS, with `flips`
    each also reversed and mirrored across the chord's normal."""
    poses = []
    for target in POSE_CHORDS[:chords]:
        turn = float(np.angle(np.exp(1j * (target - heading))))
        poses.append((turn, mirror, False))
        if flips:
            # Reflect across the line normal to the chord (S), then reverse: chord and turning stay as they were.
            # As a pose, S·R(turn)·M^mirror = R(turn')·M^(not mirror), so R(turn') = S·R(turn)·M.
            n = np.array([np.cos(target), np.sin(target)])
            c, s = np.cos(turn), np.sin(turn)
            a = (np.eye(2) - 2 * np.outer(n, n)) @ np.array([[c, -s], [s, c]]) @ np.diag([-1.0, 1.0])
            poses.append((float(np.arctan2(a[1, 0], a[0, 0])), not mirror, True))
    return poses


def canonical_frame(points: np.ndarray) -> Frame:
    """The one pose a curve is read in: of `pose_frames`' first two candidates (turning counter-clockwise, chord
    straight down; as drawn, or reversed and mirrored across the chord's normal), the one whose arc-length centroid
    lies towards the chord's end — for a loop, whose centroid lies on its chord's normal, the one whose
    product moment about the centroid (across × along the chord) is positive. Those two moves turn either statistic
    into its negative, so a curve, its reversal, its mirror image and its rotations all come to the same posed
    points (to rounding; a curve for which both are exactly zero is symmetric under the moves, or keeps the pose
    it is listed in). Computed as for a batch of one (geometry.batch.canonical_frames), so a curve gets the same
    frame alone and in a batch."""
    from curve_vae.geometry.batch import canonical_frames  # batch builds on this module

    return canonical_frames([points])[0]


def posed_frame(points: np.ndarray, rotation: float, *, mirror: bool = False, reverse: bool = False) -> Frame:
    """The frame of a curve in a pose: its bounding box taken in the posed orientation, so the posed curve fills
    the model's box as `fit_frame` makes an unposed one fill it."""
    linear = Frame((0.0, 0.0), 1.0, rotation=rotation, mirror=mirror)._linear()
    q = np.asarray(points, np.float64) @ linear
    lo, hi = q.min(axis=0), q.max(axis=0)
    center = ((lo + hi) / 2) @ linear.T
    return Frame((float(center[0]), float(center[1])), float((hi - lo).max()), rotation, mirror, reverse)


def cumulative_length(points: np.ndarray) -> np.ndarray:
    """Arc length (n,) from a polyline's (n, 2) first point to each of its points: the one place it is summed."""
    return np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(points, axis=0), axis=1))])


def arc_fractions(points: np.ndarray) -> np.ndarray:
    """Where each point of a polyline (n, 2) sits along its arc length, from 0 to 1."""
    s = cumulative_length(points)
    if s[-1] <= 0:
        raise InvalidInput("all points coincide: a curve needs at least 2 distinct points")
    return s / s[-1]


def at_fractions(curve: np.ndarray, fractions: np.ndarray) -> np.ndarray:
    """Points of a polyline (m, 2) at fractions of its index range, linearly between neighbours.

    Point j stands for fraction j/(m-1), so fractions from the same spacing give its own points.
    """
    x = np.clip(fractions, 0.0, 1.0) * (len(curve) - 1)
    idx = np.arange(len(curve))
    return np.stack([np.interp(x, idx, curve[:, 0]), np.interp(x, idx, curve[:, 1])], axis=1)


def resample_index(curves: np.ndarray, n_points: int) -> np.ndarray:
    """Curves of one length (k, n, 2) at `n_points` even steps of their point index (`at_fractions` of each at
    even fractions; `resample` with spacing "parameter"), all at once; a curve of n_points comes back as it is."""
    pts = np.asarray(curves, np.float64)
    n = pts.shape[1]
    if n == n_points:
        return pts.copy()
    x = np.linspace(0.0, 1.0, n_points) * (n - 1)
    lo = np.minimum(np.floor(x).astype(np.int64), n - 2)
    w = (x - lo)[None, :, None]
    return pts[:, lo] * (1 - w) + pts[:, lo + 1] * w


def resample(points: np.ndarray, n_points: int, *, spacing: str = "arc_length") -> np.ndarray:
    """Resample a polyline (n, 2) to n_points; end points are kept.

    spacing "arc_length": evenly along the arc (repeated points are harmless); "parameter":
    evenly along the point index, for points that are already evenly spaced in the curve's
    parameter — the data set's sampling, which arc-length spacing would move by several
    pixels where the curve's control points bunch up.
    """
    pts = np.asarray(points, dtype=np.float64)
    if spacing == "parameter":
        return pts.copy() if len(pts) == n_points else at_fractions(pts, np.linspace(0.0, 1.0, n_points))
    if spacing != "arc_length":
        raise InvalidInput(f"spacing must be 'arc_length' or 'parameter', got {spacing!r}")
    seg = np.linalg.norm(np.diff(pts, axis=0), axis=1)
    if len(pts) == n_points and np.ptp(seg) <= 1e-9 * max(seg.mean(), 1e-300):
        return pts.copy()  # already evenly spaced: untouched, so a round trip is exact
    s = cumulative_length(pts)
    if s[-1] <= 0:
        raise InvalidInput("all points coincide: a curve needs at least 2 distinct points")
    keep = np.concatenate([[True], seg > 0])  # np.interp needs strictly increasing abscissae
    s, pts = s[keep], pts[keep]
    target = np.linspace(0.0, s[-1], n_points)
    return np.stack([np.interp(target, s, pts[:, 0]), np.interp(target, s, pts[:, 1])], axis=1)
