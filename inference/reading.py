"""How a caller's curves are read: one value for the frame, pose, spacing and fitting steps a request asks for.

    Reading()                                  # the model's own reading: what it was trained for
    Reading(pose="search", spacing="search")   # the search: several poses and spacings, the closest kept
    Reading(frame="model")                     # points already in the paper's 128×128 plane, taken as they are

"auto" pose and spacing mean the model's own (its manifest's `reading`): one encoding per curve for a model
trained in geometry.canonical_frame's pose, the search for models exported before that. `resolved` makes that
concrete, so everything past it sees one of the explicit values.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

from curve_vae.inference.choices import FrameMode, Pose, Spacing
from curve_vae.inference.manifest import ReadingSpec


@dataclass(frozen=True)
class Reading:
    frame: FrameMode = "auto"
    pose: Pose = "auto"
    spacing: Spacing = "auto"
    refine: int = 0  # Levenberg–Marquardt steps on each latent after encoding (inference.fitting)

    def resolved(self, model: ReadingSpec) -> Reading:
        """The reading with "auto" replaced by the model's own; with frame "model" curves keep their pose."""
        pose = model.pose if self.pose == "auto" else self.pose
        spacing = model.spacing if self.spacing == "auto" else self.spacing
        return replace(self, pose="as_is" if self.frame == "model" else pose, spacing=spacing)

    @property
    def searches(self) -> bool:
        """Whether several candidates are encoded per curve (the pose or the spacing searched)."""
        return self.pose in ("search", "learned") or self.spacing == "search"

    @property
    def key(self) -> str:
        """The reading as a cache key."""
        return f"{self.frame}/{self.pose}/{self.spacing}/{self.refine}"
