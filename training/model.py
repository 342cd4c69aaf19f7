"""The Inception VAE of the paper (§3.5, Fig. 5) and the ablation networks of Table 1.

Curves enter and leave in the paper's 128×128 plane as (B, n_points, 2); inside, the
network works on (B, 2, n_points) scaled to about [-1, 1], so the exported ONNX graphs
take and return plain pixel coordinates and carry their own normalisation.
"""

from __future__ import annotations

import torch
from torch import nn

from curve_vae.errors import InvalidInput
from curve_vae.geometry import clamped_uniform_knots, spline_head
from curve_vae.training.config import CONV_VARIANTS, VARIANTS, ModelConfig

__all__ = ["VAE", "Encoder", "Decoder", "Inception", "ModelConfig", "VARIANTS", "count_parameters"]


class Inception(nn.Module):
    """Four parallel branches, 'same' length, concatenated to 4·f channels (paper Fig. 4).

    1×1 | 1×1 → 3 | 1×1 → 5 | maxpool 3 → 1×1, each conv followed by ReLU. The decoder's
    variant (transposed=True) uses transposed convolutions, as the reference code does.
    """

    def __init__(self, c_in: int, f: int, *, transposed: bool = False) -> None:
        super().__init__()
        conv = nn.ConvTranspose1d if transposed else nn.Conv1d

        def unit(ci: int, k: int) -> nn.Sequential:
            return nn.Sequential(conv(ci, f, k, padding=k // 2), nn.ReLU())

        self.b1 = unit(c_in, 1)
        self.b3 = nn.Sequential(unit(c_in, 1), unit(f, 3))
        self.b5 = nn.Sequential(unit(c_in, 1), unit(f, 5))
        self.bp = nn.Sequential(nn.MaxPool1d(3, stride=1, padding=1), unit(c_in, 1))

    def forward(self, x: torch.Tensor) -> torch.Tensor:  # (B, c_in, L) → (B, 4f, L)
        return torch.cat([self.b1(x), self.b3(x), self.b5(x), self.bp(x)], dim=1)


def conv_block(c_in: int, c_out: int, k: int, *, transposed: bool = False) -> nn.Sequential:
    """Valid-padded conv → ReLU (lengths shrink by k-1, or grow by k-1 when transposed)."""
    conv = nn.ConvTranspose1d if transposed else nn.Conv1d
    return nn.Sequential(conv(c_in, c_out, k), nn.ReLU())


@torch.no_grad()
def _trace(layers: nn.Sequential, x: torch.Tensor) -> list[torch.Tensor]:
    """The input of every layer and the final output, for shape probing.

    Runs in eval mode, so probing leaves BatchNorm's running statistics untouched.
    """
    was_training = layers.training
    layers.eval()
    try:
        xs = [x]
        for layer in layers:
            xs.append(layer(xs[-1]))
    finally:
        layers.train(was_training)
    return xs


def _out_len(module: nn.Sequential, c_in: int, length: int) -> tuple[int, int]:
    y = _trace(module, torch.zeros(1, c_in, length))[-1]
    return y.shape[1], y.shape[2]


def _prefix_lengths(layers: nn.Sequential, n: int, x: torch.Tensor) -> list[int]:
    """Input length each layer needs for the chain's first n outputs, in layer order."""
    inputs = _trace(layers, x)[:-1]
    needs = []
    for layer, xi in zip(reversed(layers), reversed(inputs)):
        n = _needed(layer, n, xi)
        needs.append(n)
    return needs[::-1]


def _needed(module: nn.Module, n: int, x: torch.Tensor) -> int:
    """How many leading input positions `module` needs to compute its first n outputs exactly.

    x is a sample input of the module at full length. Supports the decoder's layers:
    stride-1 (transposed) convolutions, stride-1 max-pooling, nearest upsampling,
    point-wise layers, Inception blocks and Sequential chains of them.
    """
    length = x.shape[-1]
    if isinstance(module, nn.Sequential):
        return _prefix_lengths(module, n, x)[0]
    if isinstance(module, Inception):
        return max(_needed(b, n, x) for b in (module.b1, module.b3, module.b5, module.bp))
    if isinstance(module, (nn.ConvTranspose1d, nn.Conv1d, nn.MaxPool1d)):
        k, s, p, d = (int(_first(getattr(module, a))) for a in ("kernel_size", "stride", "padding", "dilation"))
        if s != 1 or d != 1:
            raise InvalidInput(f"no prefix rule for a strided or dilated {type(module).__name__}")
        # transposed: output j reads inputs j+p-k+1 … j+p; direct: inputs j-p … j-p+k-1
        return min(n + p if isinstance(module, nn.ConvTranspose1d) else n - p + k - 1, length)
    if isinstance(module, nn.Upsample):
        if module.mode != "nearest" or module.scale_factor is None:
            raise InvalidInput("no prefix rule for a non-nearest or sized Upsample")
        scale = int(_first(module.scale_factor))
        return min(-(-n // scale), length)
    if isinstance(module, (nn.ReLU, nn.BatchNorm1d)):
        return n
    raise InvalidInput(f"no prefix rule for {type(module).__name__}")


def _first(v: int | float | tuple) -> int | float:
    return v[0] if isinstance(v, tuple) else v


class Encoder(nn.Module):
    """(B, n_points, 2) curves in the plane → mean, log-variance, each (B, latent_dim)."""

    def __init__(self, cfg: ModelConfig) -> None:
        super().__init__()
        self.cfg = cfg
        if cfg.variant == "inception":
            self.features = nn.Sequential(
                conv_block(2, 64, 5),
                Inception(64, 64),
                conv_block(256, 128, 3),
                nn.BatchNorm1d(128),
                nn.MaxPool1d(3),
                Inception(128, 128),
                conv_block(512, 256, 3),
                nn.BatchNorm1d(256),
                nn.MaxPool1d(3),
            )
        else:
            layers: list[nn.Module] = []
            c = 2
            for f, k in CONV_VARIANTS[cfg.variant]:
                layers += [conv_block(c, f, k), nn.BatchNorm1d(f), nn.MaxPool1d(3)]
                c = f
            self.features = nn.Sequential(*layers)
        self.feat_channels, self.feat_len = _out_len(self.features, 2, cfg.n_points)
        flat = self.feat_channels * self.feat_len
        self.mean = nn.Linear(flat, cfg.latent_dim)
        self.log_var = nn.Linear(flat, cfg.latent_dim)

    def forward(self, curves: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
        x = (curves.transpose(1, 2) - self.cfg.center) / self.cfg.scale  # (B, 2, N)
        h = self.features(x).flatten(1)  # (B, C·L)
        return self.mean(h), self.log_var(h)  # (B, Z), (B, Z)


#: The parameter channel's logits are this times its output: Adam moves each weight by about the learning rate
#: whatever its gradient, and the channel starts at zero beside weights already trained; unscaled, it stayed within
#: 0.6% of even increments after 70,000 curves at lr 1e-4 (×10 did not move it much further on the CPU either:
#: docs/RESULTS.md, the arc-length gap).
PARAM_GAIN = 10.0


class Decoder(nn.Module):
    """(B, latent_dim) → (B, n_points, 2) curves in the plane; no output activation.

    The layer stack yields more positions than n_points (518 for the Inception decoder)
    and the surplus tail is cropped. Only a prefix of every intermediate map reaches the
    kept points, so at inference each layer is fed just the prefix it needs
    (`self.crops`): the output equals that of the full stack (to float rounding) at about
    a third of the cost, in torch and in the exported ONNX graph alike. Training runs the
    full stack, as the paper's network does: there BatchNorm's batch statistics span the
    whole maps, and restricting them to the prefix trained worse per second in a measured
    A/B (scripts/decoder_prefix_ab.py).
    """

    # the spline head's buffers (register_buffer, with cfg.spline_ctrl): typed here, where nn.Module's __getattr__
    # would say Tensor | Module
    basis: torch.Tensor
    pinv: torch.Tensor
    knots: torch.Tensor
    closed: torch.Tensor
    dense_basis: torch.Tensor

    def __init__(self, cfg: ModelConfig, feat_channels: int, feat_len: int) -> None:
        super().__init__()
        self.cfg = cfg
        self.feat_shape = (feat_channels, feat_len)
        self.channels = 3 if cfg.spline_params else 2  # x, y (and each point's parameter increment)
        self.dense = nn.Sequential(nn.Linear(cfg.latent_dim, feat_channels * feat_len), nn.ReLU())
        up = nn.Upsample(scale_factor=3, mode="nearest")
        if cfg.variant == "inception":
            self.features = nn.Sequential(
                conv_block(256, 256, 3, transposed=True),
                nn.BatchNorm1d(256),
                up,
                Inception(256, 128, transposed=True),
                conv_block(512, 128, 3, transposed=True),
                nn.BatchNorm1d(128),
                up,
                Inception(128, 64, transposed=True),
                conv_block(256, 64, 5, transposed=True),
                nn.BatchNorm1d(64),
                up,
                nn.ConvTranspose1d(64, self.channels, 3),
            )
        else:
            layers: list[nn.Module] = []
            c = feat_channels
            for f, k in reversed(CONV_VARIANTS[cfg.variant]):
                layers += [conv_block(c, f, k, transposed=True), nn.BatchNorm1d(f), up]
                c = f
            layers.append(nn.ConvTranspose1d(c, self.channels, 3))
            self.features = nn.Sequential(*layers)
        _, out_len = _out_len(self.features, feat_channels, feat_len)
        if out_len < cfg.n_points:
            raise InvalidInput(f"decoder of {cfg.variant} yields {out_len} < {cfg.n_points} points")
        self.crops = _prefix_lengths(self.features, cfg.n_points, torch.zeros(1, *self.feat_shape))
        if cfg.spline_ctrl:
            # Fixed, not trained and not saved: rebuilt from the config, so older weights load unchanged.
            basis, pinv = spline_head(cfg.spline_ctrl, cfg.n_points)
            self.register_buffer("basis", torch.tensor(basis, dtype=torch.float32), persistent=False)
            self.register_buffer("pinv", torch.tensor(pinv, dtype=torch.float32), persistent=False)
            knots = torch.tensor(clamped_uniform_knots(cfg.spline_ctrl, 3), dtype=torch.float32)
            self.register_buffer("knots", knots, persistent=False)
            self.register_buffer("closed", last_span_mask(knots), persistent=False)
            # the spline at twice the points' density, for losses that measure the whole curve (match "closest")
            fine = spline_head(cfg.spline_ctrl, SAMPLES_PER_INTERVAL * (cfg.n_points - 1) + 1)[0]
            self.register_buffer("dense_basis", torch.tensor(fine, dtype=torch.float32), persistent=False)

    def forward(self, z: torch.Tensor, *, full: bool | None = None) -> torch.Tensor:
        """Decode to curves (B, N, 2); full runs every layer over its whole length (default: in training only)."""
        return self.decode(z, full=full)[0]

    def decode(self, z: torch.Tensor, *, full: bool | None = None) -> tuple[torch.Tensor, torch.Tensor | None]:
        """Curves (B, N, 2) and, with the spline head, their control points (B, K, 2); else None."""
        curves, ctrl, _ = self.decode_params(z, full=full)
        return curves, ctrl

    def decode_params(
        self, z: torch.Tensor, *, full: bool | None = None
    ) -> tuple[torch.Tensor, torch.Tensor | None, torch.Tensor | None]:
        """`decode`, and with learned parameters (cfg.spline_params) each point's spline parameter (B, N); else None."""
        full = self.training if full is None else full
        x = self.dense(z).view(-1, *self.feat_shape)  # (B, C, L)
        for layer, n in zip(self.features, self.crops):
            x = layer(x if full else x[:, :, :n])
        x = x[:, :, : self.cfg.n_points]  # (B, channels, N), normalised
        if not self.cfg.spline_ctrl:
            return x.transpose(1, 2) * self.cfg.scale + self.cfg.center, None, None  # (B, N, 2)
        ctrl = torch.matmul(self.pinv, x[:, :2].transpose(1, 2)) * self.cfg.scale + self.cfg.center  # (B, K, 2)
        if not self.cfg.spline_params:
            return torch.matmul(self.basis, ctrl), ctrl, None  # (B, N, 2), (B, K, 2)
        params = increments_to_params(PARAM_GAIN * x[:, 2, 1:])
        return torch.matmul(bspline_basis(params, self.knots, self.closed, 3), ctrl), ctrl, params


def increments_to_params(logits: torch.Tensor) -> torch.Tensor:
    """(B, N-1) logits -> (B, N) increasing parameters from exactly 0 to exactly 1, the steps their softmax.

    Equal logits (zero weights) give the even parameters i/(N-1)."""
    steps = torch.exp(logits - logits.amax(dim=-1, keepdim=True))
    cum = torch.cumsum(steps, dim=-1)
    return torch.cat([torch.zeros_like(cum[:, :1]), cum / cum[:, -1:]], dim=-1)


def last_span_mask(knots: torch.Tensor) -> torch.Tensor:
    """(len(knots) - 1,) bool: True at the last non-empty knot span, which `bspline_basis` closes at its end."""
    spans = knots[1:] > knots[:-1]
    last = int(torch.nonzero(spans).max())
    return torch.arange(len(spans)) == last


def bspline_basis(u: torch.Tensor, knots: torch.Tensor, closed: torch.Tensor, degree: int) -> torch.Tensor:
    """B-spline basis (…, n_ctrl) at parameters u (…) in [knots[0], knots[-1]], by Cox–de Boor's recursion.

    Differentiable in u (the curve's derivative along itself) and exported to ONNX as plain arithmetic; the last
    non-empty knot span (`closed`, from `last_span_mask`) is closed, so u = knots[-1] gives the last control point,
    as scipy's design matrix does.
    """
    t = knots
    u = u.unsqueeze(-1)
    left, right = t[:-1], t[1:]
    b = ((u >= left) & ((u < right) | (closed & (u <= right)))).to(u.dtype)
    for k in range(1, degree + 1):
        d1, d2 = t[k:-1] - t[: -k - 1], t[k + 1 :] - t[1:-k]
        r1 = torch.where(d1 > 0, 1 / torch.where(d1 > 0, d1, 1), 0)
        r2 = torch.where(d2 > 0, 1 / torch.where(d2 > 0, d2, 1), 0)
        b = (u - t[: -k - 1]) * r1 * b[..., :-1] + (t[k + 1 :] - u) * r2 * b[..., 1:]
    return b


#: Samples of the decoded spline per interval between its points in a dense decoding (VAE.forward(dense=True)).
SAMPLES_PER_INTERVAL = 2


class VAE(nn.Module):
    """Encoder + decoder. forward samples z = μ + σ·ε in training and decodes μ in eval."""

    def __init__(self, cfg: ModelConfig) -> None:
        super().__init__()
        self.cfg = cfg
        self.encoder = Encoder(cfg)
        self.decoder = Decoder(cfg, self.encoder.feat_channels, self.encoder.feat_len)

    def learn_only_params(self) -> list[nn.Parameter]:
        """Freeze everything but the head's parameter channel (its row of the decoder's last layer), BatchNorm's
        statistics included: the curves' shapes stay the weights', only where the points sit along them is
        trained. Returns the parameters left to train."""
        if not self.cfg.spline_params:
            raise InvalidInput("only the parameters can be trained with learned parameters (spline_params)")
        self.frozen_body = True
        for p in self.parameters():
            p.requires_grad_(False)
        last = self.decoder.features[-1]
        weight, bias = last.weight, last.bias
        assert isinstance(weight, nn.Parameter) and isinstance(bias, nn.Parameter), "the head: a biased convolution"
        keep = torch.zeros_like(bias)
        keep[2] = 1.0
        for p, mask in ((weight, keep.view(1, -1, 1)), (bias, keep)):
            p.requires_grad_(True)
            p.register_hook(lambda g, mask=mask: g * mask)  # the x and y rows stay as they are
        return [weight, bias]

    def learn_only_encoder(self) -> list[nn.Parameter]:
        """Freeze the decoder and every BatchNorm statistic; train the encoder's weights alone. The decoded curves
        of any latent stay the starting model's (so do /sample's and /decode's answers): only which latent a curve
        is given changes. Returns the parameters left to train."""
        self.frozen_body = True
        for p in self.decoder.parameters():
            p.requires_grad_(False)
        return [p for p in self.encoder.parameters() if p.requires_grad]

    def train(self, mode: bool = True) -> VAE:
        super().train(mode)
        if getattr(self, "frozen_body", False):
            for m in self.modules():
                if isinstance(m, nn.BatchNorm1d):
                    m.eval()  # frozen statistics: the shapes must not drift
        return self

    def forward(self, curves: torch.Tensor, *, dense: bool = False) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
        """Decoded curves (B, N, 2), latent mean and log-variance; dense: the decoded splines sampled from start to end
        at SAMPLES_PER_INTERVAL times the points' density instead (B, SAMPLES_PER_INTERVAL·(N-1)+1, 2): shapes,
        whatever the spacing (spline head)."""
        mean, log_var = self.encoder(curves)
        z = mean
        if self.training:
            z = mean + torch.randn_like(mean) * torch.exp(0.5 * log_var)  # paper eq. 1
        if not dense:
            return self.decoder(z), mean, log_var
        if not self.cfg.spline_ctrl:
            raise InvalidInput("a dense decoding needs the B-spline head (spline_ctrl)")
        _, ctrl = self.decoder.decode(z)
        assert ctrl is not None  # the spline head (above)
        return torch.matmul(self.decoder.dense_basis, ctrl), mean, log_var


def count_parameters(model: nn.Module) -> int:
    return sum(p.numel() for p in model.parameters())
