"""The kinds of curve files, as the commands' help and the readers name them (one list for both)."""

from __future__ import annotations

#: What the readers take, by extension (anything else is read as JSON).
CURVE_SUFFIXES = (".json", ".csv", ".tsv", ".npy", ".npz", ".dat", ".svg", ".dxf")
#: What the writers make, by extension.
OUTPUT_SUFFIXES = (".json", ".csv", ".npy", ".svg", ".dxf")

INPUT_HELP = (
    "curves: .json (point arrays, {curves: …}, the page's export), .csv/.tsv, .npy/.npz, airfoil .dat, .svg, .dxf, "
    "or - (JSON on stdin); of a file that marks roles (the page's exports), its inputs"
)
OUTPUT_HELP = (
    "output: .json (as the endpoint answers), .csv (points), .npy (points, float32), .svg (a path per curve, "
    "B-splines as exact Béziers), .dxf (SPLINEs, or polylines), or - for JSON on stdout"
)
