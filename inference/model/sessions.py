"""onnxruntime sessions sized to the machine: thread counts, spinning, and one encoder/decoder pair per inference slot.

Measured on this project's 2-core machine (docs/BENCHMARKS.md, bench/ceiling.py): one session with
onnxruntime's defaults runs ≈570 curves/s at batch 128, two 1-thread sessions run side by side ≈1000; the
default intra-op pool spin-waits after each run, burning 4–6 ms of CPU per single-curve request that the
other inference needed (issue 16's prototypes). So the service opens `sessions` pairs (by default one per
inference running at once), each with `intra_op_threads` threads, one inter-op thread and spinning off, and
each inference thread keeps to its own pair (`SessionPool.pair`): no two runs share a session's pool or arena.
"""

from __future__ import annotations

import itertools
import threading
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import onnxruntime as ort

from curve_vae.errors import InvalidInput
from curve_vae.inference.model.manifest import ModelLoadError

CUDA, CPU = "CUDAExecutionProvider", "CPUExecutionProvider"

SPINNING_KEYS = ("session.intra_op.allow_spinning", "session.inter_op.allow_spinning")


@dataclass(frozen=True)
class SessionConfig:
    """How each onnxruntime session is opened; `CurveRuntime.load` takes one, the service builds it from Settings."""

    intra_op_threads: int = 0  # threads of one run; 0: onnxruntime's default (one per core of the host)
    inter_op_threads: int = 1  # the graphs run sequentially: a second pool would only idle; 0: onnxruntime's default
    spinning: bool = False  # spin-wait between runs: lower latency on an idle many-core host, stolen CPU on a small one
    sessions: int = 1  # encoder/decoder pairs; inference threads are spread over them

    def options(self) -> ort.SessionOptions:
        opts = ort.SessionOptions()
        opts.intra_op_num_threads = self.intra_op_threads
        opts.inter_op_num_threads = self.inter_op_threads
        for key in SPINNING_KEYS:
            opts.add_session_config_entry(key, "1" if self.spinning else "0")
        opts.log_severity_level = 3  # errors only: provider fallbacks are reported by /model instead
        return opts


def open_pair(
    paths: tuple[Path, Path], providers: list[str], config: SessionConfig, *, require_cuda: bool
) -> tuple[ort.InferenceSession, ort.InferenceSession]:
    """Encoder and decoder sessions on `providers`; ModelLoadError with what to fix when one cannot open."""
    opened = []
    for path in paths:
        try:
            opened.append(ort.InferenceSession(str(path), sess_options=config.options(), providers=providers))
        except Exception as e:  # onnxruntime raises its own exception types
            raise ModelLoadError(f"{path}: onnxruntime cannot open it on {providers}: {e}") from e
        if require_cuda and CUDA not in opened[-1].get_providers():
            raise ModelLoadError(
                f"providers=cuda, but the CUDA provider failed to load for {path.name} (session runs on "
                f"{opened[-1].get_providers()}): check that the CUDA 12 and cuDNN 9 libraries of "
                "onnxruntime-gpu are installed and a GPU is visible, or run with --providers cpu or auto"
            )
    return opened[0], opened[1]


class SessionPool:
    """Encoder/decoder pairs; each thread that runs inference is given one pair, round robin, and keeps it."""

    def __init__(self, pairs: list[tuple[ort.InferenceSession, ort.InferenceSession]]) -> None:
        if not pairs:
            raise InvalidInput("a session pool needs at least one encoder/decoder pair")
        self.pairs = pairs
        self._next = itertools.count()
        self._local = threading.local()

    def pair(self) -> tuple[ort.InferenceSession, ort.InferenceSession]:
        """The calling thread's pair."""
        slot = getattr(self._local, "slot", None)
        if slot is None:
            slot = self._local.slot = next(self._next) % len(self.pairs)  # count() is atomic under the GIL
        return self.pairs[slot]

    def applied(self) -> dict[str, Any]:
        """The options the live sessions run with, read back from onnxruntime."""
        opts = self.pairs[0][0].get_session_options()
        return {
            "sessions": len(self.pairs),
            "intra_op_threads": opts.intra_op_num_threads,
            "inter_op_threads": opts.inter_op_num_threads,
            "spinning": opts.get_session_config_entry(SPINNING_KEYS[0]) != "0",
        }


def resolve_providers(choice: str) -> list[str]:
    """onnxruntime provider list for "cpu", "cuda" or "auto"; "cuda" fails loudly when unavailable."""
    available = ort.get_available_providers()
    if choice == "cpu":
        return [CPU]
    if choice == "cuda":
        if CUDA not in available:
            raise ModelLoadError(
                f"providers=cuda, but this onnxruntime ({ort.__version__}) offers only {available}: "
                "install the GPU build (pip install 'curve-vae[gpu]', i.e. onnxruntime-gpu, in place of "
                "onnxruntime) with CUDA 12 and cuDNN 9 libraries, or run with --providers cpu or auto"
            )
        return [CUDA, CPU]  # CPU takes any node CUDA has no kernel for
    if choice == "auto":
        return [CUDA, CPU] if CUDA in available else [CPU]
    raise ModelLoadError(f"providers must be cpu, cuda or auto, got {choice!r}")
