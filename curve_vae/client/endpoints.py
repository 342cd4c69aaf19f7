"""The endpoints as methods: each builds a `calls.Call` (the request and how to parse its answer) that a concrete
client sends — `Client` over a blocking connection, `AsyncClient` over an asynchronous one (curve_vae.client.client).
The reading's fields are typed with inference.choices' values, the service's own."""

from __future__ import annotations

from typing import Any

from curve_vae.client import calls as k
from curve_vae.client.inputs import CurvesLike, as_batch
from curve_vae.inference.choices import FrameMode, Pose, Spacing

#: A batch of curves of one length with at least this many points in all goes as a .npy body.
NPY_POINTS = 2048


class Endpoints:
    """The endpoints, each building a `calls.Call` that the concrete client sends (`_call`)."""

    npy_points = NPY_POINTS

    def _call(self, call: k.Call) -> Any:
        raise NotImplementedError

    def encode(
        self,
        curves: CurvesLike,
        *,
        frame: FrameMode | None = None,
        pose: Pose | None = None,
        spacing: Spacing | None = None,
        looks: int | None = None,
        refine: int | None = None,
    ) -> Any:
        """Latent means and log-variances (`Encoded`: mean, log_var, frames, closeness) of curves, or of one curve
        (an (n, 2) array: answered as a batch of one)."""
        fields = k.reading(frame, pose, spacing, looks, refine)
        curves = as_batch(curves, "encode")
        return self._call(k.curves_call("/encode", curves, fields, k.parse_encoded, npy_points=self.npy_points))

    def decode(
        self, latents: Any, *, n_points=None, frames=None, spacing: Spacing | None = None, output=None, metrics=None
    ) -> Any:
        """Curves (`Curves`) of latents (B, latent_dim): the model's plane, or mapped into `frames` (from encode)."""
        return self._call(
            k.decode_call(latents, {**k.output(n_points, output, metrics), **k._fields(frames=frames, spacing=spacing)})
        )

    def reconstruct(
        self,
        curves: CurvesLike,
        *,
        frame: FrameMode | None = None,
        pose: Pose | None = None,
        spacing: Spacing | None = None,
        looks: int | None = None,
        refine: int | None = None,
        n_points=None,
        output=None,
        metrics=None,
    ) -> Any:
        """Each curve through the model (`Reconstructed`: curves, mse, closeness, repaired, splines); one curve (an
        (n, 2) array) is answered as a batch of one, its curve `.curve`."""
        fields = {**k.reading(frame, pose, spacing, looks, refine), **k.output(n_points, output, metrics)}
        curves = as_batch(curves, "reconstruct")
        return self._call(
            k.curves_call("/reconstruct", curves, fields, k.parse_reconstructed, npy_points=self.npy_points)
        )

    def interpolate(
        self,
        curves: CurvesLike,
        *,
        steps=None,
        weights=None,
        frame: FrameMode | None = None,
        pose: Pose | None = None,
        spacing: Spacing | None = None,
        looks: int | None = None,
        refine: int | None = None,
        n_points=None,
        output=None,
        metrics=None,
    ) -> Any:
        """Curves between curves (`Interpolated`: curves, weights, valid, repaired, ends): an even sweep of `steps`,
        or one curve per row of `weights`. Needs two curves or more: one curve is refused (InvalidInput) before
        sending."""
        curves = as_batch(curves, "interpolate", at_least=2)
        fields = {
            **k.reading(frame, pose, spacing, looks, refine),
            **k.output(n_points, output, metrics),
            **k._fields(steps=steps, weights=None if weights is None else k.array(weights)),
        }
        return self._call(
            k.curves_call("/interpolate", curves, fields, k.parse_interpolated, npy_points=self.npy_points)
        )

    def sample(
        self,
        count: int,
        *,
        seed=None,
        temperature=None,
        prior=None,
        valid=None,
        offset=None,
        n_points=None,
        spacing: Spacing | None = None,
        frame=None,
        output=None,
        metrics=None,
    ) -> Any:
        """New curves from a latent prior (`Sampled`); the same seed gives the same curves."""
        fields = {
            **k.output(n_points, output, metrics),
            **k._fields(
                seed=seed,
                temperature=temperature,
                prior=prior,
                valid=valid,
                offset=offset,
                spacing=spacing,
                frame=frame,
            ),
        }
        return self._call(k.sample_call(count, fields))

    def augment(
        self,
        curves: CurvesLike,
        count: int,
        *,
        mode=None,
        seed=None,
        neighbours=None,
        offset=None,
        frame: FrameMode | None = None,
        pose: Pose | None = None,
        spacing: Spacing | None = None,
        looks: int | None = None,
        refine: int | None = None,
        n_points=None,
        output=None,
        metrics=None,
    ) -> Any:
        """One page of new curves between `curves` (`Augmented`, with sources, weights and redrawn); see
        `augment_chunks` for any count. Needs two curves or more: one curve is refused (InvalidInput) before
        sending."""
        curves = as_batch(curves, "augment", at_least=2)
        fields = {
            **augment_fields(mode, seed, neighbours, k.reading(frame, pose, spacing, looks, refine), n_points),
            **k._fields(offset=offset, output=output, metrics=metrics),
        }
        return self._call(k.augment_call(curves, {"count": count, **fields}, npy=False))

    def fit(self, curves: CurvesLike, *, n_ctrl=None, tolerance=None, param=None, n_points=None) -> Any:
        """Least-squares cubic B-splines of the curves (`Fitted`: one `BSplineFit` per curve); one curve (an (n, 2)
        array) is answered as a batch of one, its fit `.spline`."""
        fields = k._fields(n_ctrl=n_ctrl, tolerance=tolerance, param=param, n_points=n_points)
        return self._call(k.fit_call(as_batch(curves, "fit"), fields))

    def revolve(self, curve: Any, *, segments=None, axis=None, axis_position=None, format=None) -> Any:
        """A surface of revolution of a profile curve (`Revolved`: the mesh file's bytes, OBJ text or binary STL,
        with its format, counts, `save` and `mesh`)."""
        fields = k._fields(segments=segments, axis=axis, axis_position=axis_position, format=format)
        return self._call(k.revolve_call(curve, fields))


def augment_fields(mode, seed, neighbours, reading: dict[str, Any], n_points) -> dict[str, Any]:
    return {**k._fields(mode=mode, seed=seed, neighbours=neighbours, n_points=n_points), **reading}
