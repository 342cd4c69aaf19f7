"""The REST service: the exported VAE (ONNX) behind /encode, /decode, /reconstruct, /interpolate, /sample, /augment.

Imports onnxruntime, never torch. `service.app.create_app(settings)` builds the app;
`inference.runtime.CurveRuntime` does the work and is usable without HTTP.
"""
