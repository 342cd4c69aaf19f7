"""Every choice a request, a setting or a command offers, spelled once: the schemas, the runtime, the settings and
the command line take their values from here (`typing.get_args(Spacing)` gives argparse its `choices`)."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Literal, get_args


@dataclass(frozen=True)
class Option:
    """One reading option's documentation, value by value: the request schema's description, the command line's
    help and the error naming the values are all made of it, so adding a value means one line here beside its
    Literal (a test checks the two agree) and its implementation."""

    summary: str  # one line: the command line's help
    values: Mapping[str, str]  # each value and what it does, in the order they are shown
    before: str = ""  # the description's opening, before the values
    after: str = ""  # its closing, after them
    ge: int | None = None  # an integer option's bounds
    le: int | None = None

    def description(self, default: object) -> str:
        """The full description, the default value marked "(default)"."""
        parts = [f'"{v}"{" (default)" if v == default else ""}: {what}' for v, what in self.values.items()]
        return " ".join(p for p in (self.before, *parts, self.after) if p)


FrameMode = Literal["auto", "model"]
FRAME = Option(
    "frame of the curves: auto, anywhere at any size; model, already in the paper's 128×128 plane",
    {
        "auto": "each curve is shifted and uniformly scaled into the model's frame and results are mapped back, so "
        "curves may be anywhere at any size.",
        "model": "coordinates are already in the paper's 128×128 plane (curves about 100 units across, centred on "
        "(64, 64)) and pass untouched.",
    },
)

Pose = Literal["auto", "canonical", "search", "learned", "as_is"]
POSE = Option(
    "how each curve is turned before it is encoded, as the service's `pose`; results come back in the caller's pose",
    {
        "auto": "the reading the model was trained for (GET /model: reading.pose).",
        "canonical": "one pose the curve, its reversal, its mirror image and every rotation of it share — mirrored "
        "if it turns clockwise, its chord (first point to last) turned straight down, and reversed and mirrored end "
        "for end where its centre of mass lies towards its start — so all of them give the same curve back, at the "
        "cost of one encoding.",
        "search": "six poses (the chord turned to -90°, -45° or -135°, each also reversed and mirrored end for end) "
        "encoded and decoded, the reconstruction closest to the input kept (6× the inference).",
        "learned": 'the same candidates (and, with spacing "search", each one\'s natural reading) ranked by the '
        "model's reading ranker from their points, the first encoded (one encoding; needs a model with a ranker, "
        "GET /model: ranker).",
        "as_is": "the curve as it is listed.",
    },
    before='How a curve is turned before it is encoded (frame "auto").',
    after='Results come back in the caller\'s pose. With frame "model" curves are taken as they are.',
)

Spacing = Literal["auto", "parameter", "natural", "arc_length", "search"]
SPACING = Option(
    "how each curve's points are read along it, as the service's `spacing`",
    {
        "auto": "the model's own reading (GET /model: reading.spacing).",
        "parameter": "the points as given, interpolated along their order (50, 161 or 500 samples of a curve give "
        "the same result).",
        "natural": "the curve read at even steps of the parameters of the cubic B-spline with 10 control points "
        "fitted to it closest (the paper's curves' own spacing, whatever spacing they came in).",
        "arc_length": "every curve resampled evenly by arc length, and returned curves spaced so.",
        "search": '"parameter" and each natural reading tried, the reconstruction closest to the input kept (2–3× '
        "the inference).",
    },
    before="How the points of a curve are read along it.",
    after="Returned curves of `n_points` are at the model's own spacing (evenly in its spline parameter) except "
    'with "arc_length".',
)

#: Most looks again a request may ask for (each one encoder and one decoder pass a curve; inference/looking.py).
MAX_LOOKS = 5

LOOKS = Option(
    "looks again after reading: fixed-point steps z ← z + E(x) − E(D(z)), as the service's `looks`",
    {},
    before="Looks again after reading. Each look re-encodes the decoded curve and moves the latent by what the "
    "encoder reads differently from the input (z ← z + E(x) − E(D(z))), kept only where it brings the decoding "
    "closer: one encoder and one decoder pass a curve each, no training, no Jacobian. In /encode the returned means "
    "are the latents after the looks; `refine` starts from them.",
    ge=0,
    le=MAX_LOOKS,
)

#: Most fitting steps a request may ask for (each costs about 7 decoder runs per curve: a Jacobian of 32 runs every
#: 5th step, one run per step; inference/fitting.py).
MAX_REFINE_STEPS = 30

REFINE = Option(
    "Levenberg–Marquardt fitting steps on each latent after encoding, as the service's `refine`",
    {},
    before="Fitting steps (default 0: none). After encoding, each curve's latent is refined by this many "
    "Levenberg–Marquardt steps that bring the decoded curve closer to the input's own points, each point "
    "measured to its closest point on the curve, and the returned points are those closest points: a closer "
    "fit for several times the compute of a plain reconstruction (docs/RESULTS.md has the trade-off). "
    "Needs a model with a B-spline head; a request's work, steps × (input points + 300 per curve), is "
    "limited by the server (GET /model: limits.max_refine_work). In /encode, the returned means are the "
    "refined latents; in /interpolate the refined latents are mixed, so the ends of a sweep are the refined "
    "reconstructions.",
    ge=0,
    le=MAX_REFINE_STEPS,
)

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

#: Where a reconstruction's points are placed on its spline, as a model's manifest records it (spline.placement):
#: "closest", each input point at its closest point on the decoded spline, kept in order (never further from the input
#: than "index" on the same spline); "index", point i at the head's parameter i (models before 0.10.1).
SplinePlacement = Literal["closest", "index"]
#: What a server or a command may ask for: one of those whatever the manifest says, or "model": as it says.
Placement = Literal["model", SplinePlacement]

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
