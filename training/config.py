"""Model and training configurations: frozen dataclasses, torch-free so the CLI can list them.

Checkpoints store `asdict(config)`, so export and evaluation rebuild a model from the
checkpoint alone, whatever the defaults here become.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

from curve_vae.errors import InvalidInput

# Table 1's shallow networks: (filters, kernel) of each conv layer of the encoder; the
# decoder mirrors them with transposed convolutions. CNN_6 is the Inception network.
CONV_VARIANTS: dict[str, tuple[tuple[int, int], ...]] = {
    "cnn1": ((64, 3), (128, 3)),  # two conv layers, kernel 3
    "cnn2": ((64, 5), (128, 5)),  # kernel 5
    "cnn3": ((64, 5), (128, 3)),  # mixed kernels 5 then 3
    "cnn4": ((128, 5), (256, 3)),  # CNN_3 with twice the filters
    "cnn5": ((64, 5), (128, 3), (256, 3)),  # three conv layers
}
VARIANTS = (*CONV_VARIANTS, "inception")
ALIASES = {"cnn6": "inception"}


@dataclass(frozen=True)
class ModelConfig:
    variant: str = "inception"  # "inception" (= CNN_6, the paper's model) or cnn1 … cnn5
    latent_dim: int = 32  # paper Table 2: 32 balances accuracy and cost
    n_points: int = 161  # points per curve, fixed by the network's shape arithmetic
    center: float = 64.0  # plane centre: inputs are shifted by this ...
    scale: float = 64.0  # ... and divided by this, so the data lie in about [-1, 1]
    # B-spline output head: decoded points are projected onto clamped uniform cubic B-splines with
    # this many control points (0: raw points). A fixed projector, no weights: it removes the
    # stride-3 upsampling's zig-zag; 7k + 3 keeps the data's knots, so data curves pass unchanged.
    spline_ctrl: int = 0
    # With the spline head: each point's spline parameter is the decoder's own (a third output channel whose
    # softmax gives the increments between consecutive points), so points may sit at any spacing along the
    # spline, such as arc length; off: point i sits at i/(n_points-1). Zero weights in that channel give the
    # even parameters exactly, so a model without it continues with the channel added (checkpoint.widen).
    spline_params: bool = False

    def __post_init__(self) -> None:
        object.__setattr__(self, "variant", ALIASES.get(self.variant.lower(), self.variant.lower()))
        if self.variant not in VARIANTS:
            raise InvalidInput(f"unknown variant {self.variant!r}; choose one of {', '.join(VARIANTS)}")
        if self.latent_dim < 1:
            raise InvalidInput(f"latent_dim must be ≥ 1, got {self.latent_dim}")
        if self.spline_ctrl and not 4 <= self.spline_ctrl <= self.n_points:
            raise InvalidInput(f"spline_ctrl must be 0 (off) or 4 … {self.n_points}, got {self.spline_ctrl}")
        if self.spline_params and not self.spline_ctrl:
            raise InvalidInput("spline_params needs the B-spline head (spline_ctrl > 0)")

    def same_weights(self, other: ModelConfig) -> bool:
        """Whether the two configs have the same trainable weights (the spline head has none of its own)."""

        def key(c: ModelConfig) -> tuple[ModelConfig, bool]:  # learned parameters add a channel; the head none
            return replace(c, spline_ctrl=0, spline_params=False), c.spline_params

        return key(self) == key(other)


SCHEDULES = ("onecycle", "cosine", "constant", "plateau")
MATCHES = ("index", "closest", "twin", "mixed")
#: The matches that learn from each curve beside its twin (DataConfig.twins).
TWIN_MATCHES = ("twin", "mixed")


@dataclass(frozen=True)
class TrainConfig:
    epochs: int = 30  # CPU budget; the paper ran 900 epochs on a GPU
    batch_size: int = 128  # paper §3.5 (global batch; split across DDP processes)
    lr: float = 1e-3  # paper §3.5 (Adam); peak rate for onecycle
    schedule: str = "onecycle"  # onecycle | cosine | constant | plateau
    warmup: float = 0.1  # onecycle: fraction of steps spent warming up
    beta: float = 1e-3  # KL weight
    lap_weight: float = 1.0  # Laplacian (smoothness) weight; 0 disables the term
    grad_clip: float = 0.0  # clip the gradient norm to this (0: off)
    patience: int = 0  # stop after this many epochs without a better validation MSE (0: off)
    bf16: bool = False  # bf16 autocast (AMX on recent Xeons, tensor cores on GPUs)
    compile: bool = False  # torch.compile the model
    seed: int = 0  # weight init, batch order and ε of the reparameterisation
    threads: int = 0  # torch intra-op threads (0: torch's default)
    device: str = "auto"  # auto | cpu | cuda
    train_limit: int = 0  # use only the first N training curves (0: all)
    time_budget: float = 0.0  # seconds of training: the schedule follows elapsed time, not steps (0: off)
    snapshots: int = 0  # keep the weights of the latest N epochs as epoch-NNNN.pt, for curve-vae average
    only_params: bool = False  # train only the head's parameter channel (VAE.learn_only_params)
    # index: eq. 4, point i to point i; closest: each point to its closest point (spacing-free); twin: eq. 4 against
    # the curve's twin, the same curve evenly in its own parameter (data twins): whatever the input's spacing, the
    # decoder's even parameters fall where the curve's own do; mixed: index for curves drawn evenly in their own
    # parameter (equal to their twins), closest for the rest (losses.mixed_loss)
    match: str = "index"
    only_encoder: bool = False  # train only the encoder; decoder, BatchNorm statistics frozen (VAE.learn_only_encoder)

    def __post_init__(self) -> None:
        if self.schedule not in SCHEDULES:
            raise InvalidInput(f"schedule must be one of {', '.join(SCHEDULES)}, got {self.schedule!r}")
        if self.time_budget and self.schedule == "plateau":
            raise InvalidInput("a time budget needs a onecycle, cosine or constant schedule, not plateau")
        if self.snapshots < 0:
            raise InvalidInput(f"snapshots must be ≥ 0, got {self.snapshots}")
        if self.match not in MATCHES:
            raise InvalidInput(f"match must be one of {', '.join(MATCHES)}, got {self.match!r}")
        if self.only_params and self.only_encoder:
            raise InvalidInput("only_params and only_encoder exclude each other: pick one part to train")
        if self.epochs < 1 or self.batch_size < 1 or self.lr <= 0:
            raise InvalidInput("epochs and batch_size must be ≥ 1 and lr > 0")
