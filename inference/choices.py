"""Every choice a request, a setting or a command offers, spelled once: the schemas, the runtime, the settings and
the command line take their values from here (`typing.get_args(Spacing)` gives argparse its `choices`)."""

from __future__ import annotations

from typing import Literal, get_args

#: "auto": each curve shifted and uniformly scaled into the model's plane, results mapped back; "model": the points
#: are in the paper's 128×128 plane already.
FrameMode = Literal["auto", "model"]

#: How a curve is turned before it is encoded. "canonical": the one pose geometry.canonical_frame gives the curve
#: and its reversal, mirror image and rotations alike (one encoding); "search": six candidate poses encoded and
#: decoded, the closest reconstruction kept (geometry.pose_frames); "learned": the search's candidates ranked by
#: the model's reading ranker (inference.ranker) and only its first two encoded; "as_is": as it is listed; "auto":
#: the reading the model was trained for (its manifest's `reading.pose`).
Pose = Literal["auto", "canonical", "search", "learned", "as_is"]

#: How a curve's points are read along it. "parameter": as given, interpolated along their order; "natural": at
#: even steps of the parameters of the cubic B-spline fitted to it (geometry.natural_params); "arc_length": evenly
#: by arc length; "search": "parameter" and each natural reading tried, the closest reconstruction kept; "auto":
#: the model's own reading (its manifest's `reading.spacing`).
Spacing = Literal["auto", "parameter", "natural", "arc_length", "search"]

#: The poses and spacings a model's manifest may name as its own reading (everything but "auto").
ModelPose = Literal["canonical", "search", "learned", "as_is"]
ModelSpacing = Literal["parameter", "natural", "arc_length", "search"]

#: How returned curves are given: points, B-splines, or both.
Output = Literal["points", "bspline", "both"]

#: The latent distributions /sample draws from besides a named prior: the mixture shipped with the model, N(0, I).
BuiltinPrior = Literal["learned", "standard"]

#: How many seed curves one augmented curve mixes: two (paper eq. 9) or three (eq. 10).
AugmentMode = Literal["pair", "triplet"]
SOURCES_PER_MODE: dict[str, int] = {"pair": 2, "triplet": 3}

#: The body /augment answers: JSON pages, or one streamed .npy file.
AugmentFormat = Literal["json", "npy"]

#: Where a reconstruction's points are placed on its spline: "closest" (each input point at its closest point,
#: kept in order), "index" (point i at the head's parameter i); "model": as the model's manifest says.
Placement = Literal["model", "closest", "index"]

#: onnxruntime providers: "cuda" must load or the service does not start; "auto" takes CUDA where it is.
Providers = Literal["cpu", "cuda", "auto"]

#: How /fit parametrises a curve's points.
FitParam = Literal["chord", "uniform"]

#: /revolve: the axis a profile turns about, and the mesh file it answers.
Axis = Literal["x", "y"]
MeshFormat = Literal["obj", "stl"]


def choices(kind: object) -> tuple[str, ...]:
    """The values of a Literal choice, for argparse's `choices` and for messages."""
    return tuple(get_args(kind))
