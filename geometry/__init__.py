"""Curve geometry shared by training and service: pure numpy/scipy, no torch.

One place for everything the project knows about curves: B-spline sampling and fitting,
arc-length resampling, frame normalisation, adaptation of any curve to the model's plane and
point count and back, self-intersection and smoothness metrics.
A curve is an array of shape (n_points, 2); a batch is (batch, n_points, 2).
"""

from curve_vae.geometry.adapt import BeyondFloat32, polyline_to_caller, spline_to_caller, to_model_plane
from curve_vae.geometry.bspline import (
    BSplineFit,
    arc_length_params,
    clamped_uniform_knots,
    closest_params,
    evaluate_bspline,
    fit_bspline,
    fit_bspline_auto,
    params_at_arc_fractions,
    random_control_points,
    sample_bspline,
    spline_head,
)
from curve_vae.geometry.frame import (
    MODEL_SIZE,
    Frame,
    arc_centroid,
    arc_fractions,
    at_fractions,
    blend_frames,
    canonical_frame,
    cumulative_length,
    fit_frame,
    pose_frames,
    posed_frame,
    resample,
    signed_turning,
    turns_clockwise,
)
from curve_vae.geometry.matching import ordered_closest_params
from curve_vae.geometry.mesh import Mesh, revolve
from curve_vae.geometry.metrics import (
    closeness,
    closest_squared_distances,
    curve_length,
    diagonal,
    mse_per_curve,
    self_intersects,
    smoothness,
    turning_angles,
)
from curve_vae.geometry.mixing import simplex_grid, simplex_grid_size
from curve_vae.geometry.natural import natural_params, natural_readings, natural_readings_of

__all__ = [
    "MODEL_SIZE",
    "cumulative_length",
    "arc_length_params",
    "arc_fractions",
    "at_fractions",
    "BeyondFloat32",
    "BSplineFit",
    "Frame",
    "Mesh",
    "arc_centroid",
    "blend_frames",
    "canonical_frame",
    "clamped_uniform_knots",
    "closest_params",
    "closeness",
    "diagonal",
    "closest_squared_distances",
    "curve_length",
    "evaluate_bspline",
    "fit_bspline",
    "fit_bspline_auto",
    "natural_params",
    "natural_readings",
    "natural_readings_of",
    "fit_frame",
    "mse_per_curve",
    "params_at_arc_fractions",
    "polyline_to_caller",
    "pose_frames",
    "posed_frame",
    "random_control_points",
    "resample",
    "revolve",
    "sample_bspline",
    "self_intersects",
    "simplex_grid",
    "simplex_grid_size",
    "signed_turning",
    "turns_clockwise",
    "ordered_closest_params",
    "smoothness",
    "spline_head",
    "spline_to_caller",
    "to_model_plane",
    "turning_angles",
]
