"""An Open Inference Protocol client (tritonclient.http): the same code calls curve-vae's /v2 endpoints or NVIDIA
Triton serving the repository `curve-vae triton` writes; only the URL and the model names differ.

    pip install "tritonclient[http]" numpy                      # not a dependency of curve-vae
    python scripts/oip_client.py --url 127.0.0.1:8000                          # curve-vae serve
    python scripts/oip_client.py --url 127.0.0.1:8000 --prefix curve_vae_      # tritonserver

It encodes a half ellipse given in the model's plane at the encoder's point count (raw tensors: no frames, no
resampling; docs/DEPLOYMENT.md says how the REST routes' geometry relates), decodes its latent mean and prints
how far the reconstruction lies from it.
"""

from __future__ import annotations

import argparse
import sys

import numpy as np


def main(argv: list[str] | None = None) -> int:
    import tritonclient.http as httpclient

    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--url", default="127.0.0.1:8000", help="host:port of the server (default: 127.0.0.1:8000)")
    p.add_argument("--prefix", default="", help='model name prefix: "" for curve-vae, "curve_vae_" for Triton')
    p.add_argument("--api-key", default="", help="curve-vae's API key, where CURVE_VAE_API_KEYS is set")
    a = p.parse_args(argv)
    encoder, decoder = f"{a.prefix}encoder", f"{a.prefix}decoder"
    headers = {"X-API-Key": a.api_key} if a.api_key else None

    client = httpclient.InferenceServerClient(url=a.url)
    if not (client.is_server_ready() and client.is_model_ready(encoder, headers=headers)):
        print(f"{a.url}: not ready", file=sys.stderr)
        return 1
    meta = client.get_model_metadata(encoder, headers=headers)
    (curves_in,) = meta["inputs"]
    n_points = curves_in["shape"][1]  # [-1, n_points, 2]: read from the server, not assumed

    t = np.linspace(0.0, np.pi, n_points)
    curves = np.stack([64 + 40 * np.cos(t), 64 + 30 * np.sin(t)], axis=1)[None].astype(np.float32)
    x = httpclient.InferInput(curves_in["name"], list(curves.shape), "FP32")
    x.set_data_from_numpy(curves, binary_data=False)  # JSON tensors: curve-vae does not serve the binary extension
    out = [httpclient.InferRequestedOutput("mean", binary_data=False)]
    mean = client.infer(encoder, [x], outputs=out, headers=headers).as_numpy("mean")

    z = httpclient.InferInput("latent", list(mean.shape), "FP32")
    z.set_data_from_numpy(mean, binary_data=False)
    out = [httpclient.InferRequestedOutput("curves", binary_data=False)]
    decoded = client.infer(decoder, [z], outputs=out, headers=headers).as_numpy("curves")
    mse = float(np.mean((decoded - curves) ** 2))
    print(f"{a.url}: {encoder} {curves.shape} → mean {mean.shape} → {decoder} → {decoded.shape}, MSE {mse:.4f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
