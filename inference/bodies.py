"""The JSON bodies of the endpoints, built from the runtime's results, shared by the REST routes and the offline CLI.

`curve-vae encode|reconstruct|sample|augment|fit` write exactly what POST /encode, /reconstruct, /sample, /augment
and /fit answer for the same request, because both build their bodies here. Arrays stay numpy (the service's
orjson writes them directly; the CLI's JSON writer turns them into lists).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np

from curve_vae.geometry import Frame, curve_length, fit_bspline, fit_bspline_auto, self_intersects, smoothness
from curve_vae.inference.errors import InputError
from curve_vae.inference.exploring import Explored
from curve_vae.inference.results import Augmented, Curves, Encoding, Interpolation, Reconstruction, Sampled, Spline


def frames_json(frames: Sequence[Frame | None]) -> list[dict[str, Any]] | None:
    """Frames as the API reports them; None for frame "model"."""
    if not frames or frames[0] is None:
        return None
    return [
        {"center": list(f.center), "size": f.size, "rotation": f.rotation, "mirror": f.mirror, "reverse": f.reverse}
        for f in frames
        if f is not None
    ]


def with_metrics(body: dict[str, Any], curves: Sequence[np.ndarray] | np.ndarray, wanted: bool) -> dict[str, Any]:
    """`body` plus the per-curve quality measures when the request asked for them: `curves` a list of (n, 2) arrays
    or one (n_curves, n, 2) array."""
    return {**body, "metrics": curve_metrics(curves)} if wanted else body


def with_output(body: dict[str, Any], splines: Sequence[Spline] | None, output: str = "points") -> dict[str, Any]:
    """`body` with its curves as the request's `output` asks: "points" (`curves`), "bspline" (`splines`) or "both"."""
    if output == "points" or splines is None:
        return body
    out = {**body, "splines": [sp.json() for sp in splines]}
    if output == "bspline":
        out.pop("curves", None)
    return out


def encode_body(enc: Encoding) -> dict[str, Any]:
    # float64 as the JSON always carried: orjson would write float32 at float32's shorter precision
    body = {
        "mean": enc.mean.astype(np.float64),
        "log_var": enc.log_var.astype(np.float64),
        "frames": frames_json(enc.frames),
    }
    if enc.closeness is not None:  # the reading decoded each latent (closest placement): how close it came
        body["closeness"] = enc.closeness.json()
    return body


def decode_body(made: Curves, *, metrics: bool = False, output: str = "points") -> dict[str, Any]:
    body = with_metrics({"curves": made.curves.tolist()}, made.curves, metrics)
    return with_output(body, made.splines, output)


def reconstruct_body(rec: Reconstruction, *, metrics: bool = False, output: str = "points") -> dict[str, Any]:
    body = {
        "curves": [np.ascontiguousarray(c) for c in rec.curves],
        "mse": rec.mse,
        "closeness": rec.closeness.json(),
        "repaired": rec.repaired.tolist(),
    }
    return with_output(with_metrics(body, rec.curves, metrics), rec.splines, output)


def interpolate_body(mix: Interpolation, *, metrics: bool = False, output: str = "points") -> dict[str, Any]:
    body = {
        "weights": mix.weights,
        "curves": np.ascontiguousarray(mix.curves),
        "frames": frames_json(mix.frames),
        "valid": mix.valid.tolist(),
        "repaired": mix.repaired.tolist(),
        "ends": mix.ends.json(),
    }
    return with_output(with_metrics(body, mix.curves, metrics), mix.splines, output)


def sample_body(made: Sampled, *, metrics: bool = False) -> dict[str, Any]:
    body = {
        "latents": made.latents.tolist(),
        "curves": made.curves.tolist(),
        "seed": made.seed,
        "offset": made.offset,
        "prior": made.prior,
        "rejected": made.rejected,
        "invalid": made.invalid,
        # a prior of users' curves places each curve in the frame of its nearest reference curve: say which
        **({"frames": frames_json(made.frames)} if made.prior not in ("learned", "standard") else {}),
    }
    return with_metrics(body, made.curves, metrics)


def augment_body(made: Augmented, *, metrics: bool = False) -> dict[str, Any]:
    body = {
        "curves": made.curves.tolist(),
        "sources": made.sources.tolist(),
        "weights": made.weights.tolist(),
        "frames": frames_json(made.frames),
        "seed": made.seed,
        "offset": made.offset,
        "redrawn": made.redrawn,
        "invalid": made.invalid,
    }
    return with_metrics(body, made.curves, metrics)


def fit_body(
    curves: Sequence[np.ndarray],
    n_ctrl: int | None = None,
    *,
    param: str = "chord",
    n_points: int | None = None,
    tolerance: float = 1e-3,
) -> dict[str, Any]:
    """Least-squares cubic B-spline of each curve (geometry.fit_bspline; without n_ctrl, fit_bspline_auto picks the
    fewest control points within `tolerance` of the diagonal); InputError names a curve it cannot fit."""
    fits = []
    for i, c in enumerate(curves):
        if n_ctrl is not None and len(c) < n_ctrl:
            raise InputError(
                ("curves", i),
                f"n_ctrl={n_ctrl} control points need at least as many points, got {len(c)}; "
                "omit n_ctrl to have it chosen",
            )
        try:
            with np.errstate(all="ignore"):
                f = (
                    fit_bspline(c, n_ctrl, param=param)
                    if n_ctrl is not None
                    else fit_bspline_auto(c, tolerance=tolerance, param=param)
                )
        except (ValueError, np.linalg.LinAlgError) as e:
            raise InputError(("curves", i), _unfittable(n_ctrl, e)) from e
        if not (np.isfinite(f.control_points).all() and np.isfinite([f.rms_error, f.max_error]).all()):
            raise InputError(("curves", i), _unfittable(len(f.control_points)))
        out: dict[str, Any] = {
            "control_points": f.control_points.tolist(),
            "knots": f.knots.tolist(),
            "degree": f.degree,
            "n_ctrl": len(f.control_points),
            "rms_error": f.rms_error,
            "max_error": f.max_error,
        }
        if n_points is not None:
            out["curve"] = f.evaluate(n_points).tolist()
        fits.append(out)
    return {"fits": fits}


def _unfittable(n_ctrl: int | None, error: Exception | None = None) -> str:
    why = f" ({error})" if error is not None and len(str(error)) < 120 else ""
    count = f"{n_ctrl}" if n_ctrl is not None else "any number of"
    return (
        f"no unique least-squares spline with {count} control points{why}: some knot span holds too few of the "
        'curve\'s points; use fewer control points, more points, or param "uniform"'
    )


def mesh_file(mesh: Any, *, points: int, segments: int, axis: str, fmt: str) -> bytes:
    """A surface of revolution as the file /revolve answers and `curve-vae revolve` writes: binary STL, or OBJ text
    that says what it is."""
    if fmt == "stl":
        with np.errstate(all="ignore"):  # normals of huge triangles: STL readers recompute them
            return mesh.to_stl()
    comment = f"curve-vae surface of revolution: {points}-point profile, {segments} segments about the {axis} axis"
    return mesh.to_obj(comment=comment).encode()


def curve_metrics(curves: Sequence[np.ndarray] | np.ndarray) -> list[dict[str, Any]]:
    """Per curve (a list of (n, 2) arrays or one (n_curves, n, 2) array), as the API reports it: smoothness (paper
    §3.4, degrees), self-intersection, length."""
    out = []
    for c in curves:
        with np.errstate(all="ignore"):
            smooth = {name: _number(v) for name, v in smoothness(c).items()}
            length = _number(curve_length(c))
        out.append({"smoothness": smooth, "self_intersects": bool(self_intersects(c)), "length": length})
    return out


def _number(value: Any) -> float | None:
    """A JSON number, or null where float64 overflowed (curves near the float limit)."""
    v = float(value)
    return v if math.isfinite(v) else None


def explore_body(made: Explored, *, metrics: bool = False, output: str = "points") -> dict[str, Any]:
    d = made.directions
    body = {
        "curves": made.curves.tolist(),
        "offsets": made.offsets.tolist(),
        "valid": made.valid.tolist(),
        "directions": [{"deviation": float(v), "share": float(s)} for v, s in zip(d.deviations, d.shares)],
        "prior": made.prior,
    }
    return with_output(with_metrics(body, made.curves, metrics), made.splines, output)
