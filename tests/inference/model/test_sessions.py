"""inference.model.sessions: onnxruntime sessions as the service opens them — the options read back from onnxruntime,
one
encoder/decoder pair per inference thread (round robin, kept), and the errors that say what to fix when a graph or
a provider cannot be had."""

import threading

import onnxruntime as ort
import pytest

from curve_vae.errors import InvalidInput
from curve_vae.inference.model.manifest import ModelLoadError
from curve_vae.inference.model.sessions import (
    CPU,
    SPINNING_KEYS,
    SessionConfig,
    SessionPool,
    open_pair,
    resolve_providers,
)


def _paths(model_dir):
    return (model_dir / "encoder.onnx", model_dir / "decoder.onnx")


@pytest.mark.parametrize("spinning, flag", [(False, "0"), (True, "1")], ids=["quiet", "spinning"])
def test_the_options_carry_the_threads_and_spinning(spinning, flag):
    opts = SessionConfig(intra_op_threads=3, inter_op_threads=2, spinning=spinning).options()
    assert (opts.intra_op_num_threads, opts.inter_op_num_threads) == (3, 2)
    assert [opts.get_session_config_entry(k) for k in SPINNING_KEYS] == [flag, flag]  # both pools alike
    assert opts.log_severity_level == 3  # errors only


def test_an_opened_pool_reports_the_options_onnxruntime_runs_with(model_dir):
    config = SessionConfig(intra_op_threads=1, spinning=True, sessions=2)
    pool = SessionPool([open_pair(_paths(model_dir), [CPU], config, require_cuda=False) for _ in range(2)])
    assert pool.applied() == {"sessions": 2, "intra_op_threads": 1, "inter_op_threads": 1, "spinning": True}
    encoder, decoder = pool.pairs[0]
    assert encoder.get_inputs()[0].name != decoder.get_inputs()[0].name  # the two graphs, in that order
    assert encoder.get_providers() == [CPU]


def test_each_thread_is_given_a_pair_round_robin_and_keeps_it():
    pairs = [("encoder 0", "decoder 0"), ("encoder 1", "decoder 1")]  # pair() hands them out, never runs them
    pool = SessionPool(pairs)  # type: ignore[arg-type]
    got: list[tuple[object, object]] = []

    def worker() -> None:
        first = pool.pair()
        assert pool.pair() is first  # the same pair on every later call of this thread
        got.append(first)

    for _ in range(4):  # one after another, so the order of the first calls is known
        t = threading.Thread(target=worker)
        t.start()
        t.join()
    assert got == [pairs[0], pairs[1], pairs[0], pairs[1]]


def test_a_pool_without_pairs_is_refused():
    with pytest.raises(InvalidInput, match="at least one encoder/decoder pair"):
        SessionPool([])


def test_a_file_onnxruntime_cannot_open_is_named(tmp_path):
    bad = tmp_path / "encoder.onnx"
    bad.write_bytes(b"not a graph")
    with pytest.raises(
        ModelLoadError, match=r"encoder\.onnx: onnxruntime cannot open it on \['CPUExecutionProvider'\]"
    ):
        open_pair((bad, bad), [CPU], SessionConfig(), require_cuda=False)


def test_requiring_cuda_on_sessions_that_run_without_it_names_the_fix(model_dir):
    # CPU only asked for, CUDA required: whatever the machine, the session runs without CUDA
    with pytest.raises(ModelLoadError, match=r"CUDA provider failed to load for encoder\.onnx.*--providers cpu"):
        open_pair(_paths(model_dir), [CPU], SessionConfig(), require_cuda=True)


@pytest.mark.parametrize("choice", ["gpu", "CPU", ""])
def test_an_unknown_provider_choice_is_refused_naming_the_choices(choice):
    with pytest.raises(ModelLoadError, match=f"providers must be cpu, cuda or auto, got {choice!r}"):
        resolve_providers(choice)


@pytest.mark.skipif("CUDAExecutionProvider" in ort.get_available_providers(), reason="CUDA is available here")
def test_cuda_where_it_cannot_load_is_an_error_naming_the_fix():
    with pytest.raises(ModelLoadError, match="onnxruntime-gpu"):
        resolve_providers("cuda")


def test_auto_takes_cuda_only_when_available():
    expected = (
        "CUDAExecutionProvider" if "CUDAExecutionProvider" in ort.get_available_providers() else "CPUExecutionProvider"
    )
    assert resolve_providers("auto")[0] == expected
    assert resolve_providers("cpu") == ["CPUExecutionProvider"]
