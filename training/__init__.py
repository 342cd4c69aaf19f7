"""Training package: data set, Inception VAE, losses, trainer, ONNX export, evaluation."""
