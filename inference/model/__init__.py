"""The model at inference time: its files' contract (`manifest`), opening a model directory (`opening`), the one class
that runs its ONNX graphs, the encoder's, the decoder's and the learned parts' (`graphs`), the sessions and threads
they run on (`sessions`, `cpus`, `batching`), and the shipped models by name (`shipped`)."""
