"""The model at inference time, on numpy arrays: no HTTP, no torch.

`CurveRuntime.load(model_dir)` checks a model directory, opens its ONNX graphs (`inference.model`: `manifest`,
`opening`, `graphs`, `sessions`) and brings any caller's curve to them and back: the reading, in this package
itself (`runtime`, `reading`, `reader`, `placing`, `results`, with `geometry`); new curves from the model
(`inference.generation`: `sampling`, `prior`, `augmenting`, `exploring`, `mixing`) sit beside it. The REST service
(`curve_vae.service`), the command line, training's export and evaluation and the client all use it.
"""
