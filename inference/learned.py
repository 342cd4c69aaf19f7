"""A learned part beside a model's graphs (the reading ranker, the spacing guesser) as the ONNX graph its torch module
was exported to (training/parts.py): one session, opened like the model's own graphs, whose run releases the GIL —
so that two threads of one process read two requests on two cores.

Each part's graph takes one float32 input, (batch, channels, points), and gives one output per row; its shape is
checked when it opens, so that a graph of another part, or of another model's point count, is refused there.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import onnxruntime as ort

from curve_vae.errors import InvalidInput
from curve_vae.inference.sessions import SessionConfig


class PartGraph:
    """One learned part's session and the input shape it takes (None where any size goes)."""

    def __init__(self, session: ort.InferenceSession) -> None:
        self.session = session
        inp = session.get_inputs()[0]
        self.input_name = inp.name
        self.input_shape = [d if isinstance(d, int) else None for d in inp.shape]

    @classmethod
    def open(
        cls, path: str | Path, *, shape: tuple[int | None, ...], providers: list[str], sessions: SessionConfig
    ) -> PartGraph:
        """The graph at `path`, whose input must be (batch, *shape) (None: any size); else InvalidInput saying
        what it takes. A numpy .npz of weights (a model from before 0.14.0) is refused with how to convert it."""
        path = Path(path)
        if path.suffix == ".npz":
            raise InvalidInput(
                "numpy weights, which this runtime no longer reads: convert them to ONNX with "
                f"`curve-vae {path.stem} export {path} --model-dir {path.parent} --force` (the training extra)"
            )
        try:
            session = ort.InferenceSession(str(path), sess_options=sessions.options(), providers=providers)
        except Exception as e:  # onnxruntime raises its own exception types
            raise InvalidInput(f"onnxruntime cannot open it: {e}") from e
        graph = cls(session)
        want = [None, *shape]
        got = graph.input_shape
        if len(got) != len(want) or any(w is not None and g != w for g, w in zip(got, want)):
            raise InvalidInput(f"its graph takes {_shape(got)}; this part takes {_shape(want)}")
        return graph

    def run(self, inputs: np.ndarray) -> np.ndarray:
        """The graph's output for (batch, …) float32 inputs."""
        return self.session.run(None, {self.input_name: np.ascontiguousarray(inputs, np.float32)})[0]


def _shape(dims: list[int | None]) -> str:
    return "(" + ", ".join("any" if d is None else str(d) for d in dims) + ")"
