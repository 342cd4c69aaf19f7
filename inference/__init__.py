"""The model at inference time, on numpy arrays: no HTTP, no torch.

`CurveRuntime.load(model_dir)` checks a model directory (`manifest`), opens its ONNX graphs (`graphs`, `sessions`)
and brings any caller's curve to them and back (`runtime`, with `geometry`); sampling from a latent prior
(`sampling`, `prior`), augmentation (`augmenting`) and the closer fit of `refine` (`fitting`) sit beside it. The REST
service (`curve_vae.service`), the command line, training's export and evaluation and the client all use it.
"""
