"""training/train.py: the trainer. Training the encoder alone (every latent decodes as before; only which latent a
curve gets changes), the reconstruction each match measures, and a run killed mid-epoch resumed from its checkpoint."""

import json
import os
import signal
import subprocess
import sys
import time

import numpy as np
import pytest
import torch

from curve_vae.cli import main
from curve_vae.training.checkpoint import load_checkpoint
from curve_vae.training.config import ModelConfig, TrainConfig
from curve_vae.training.data import DataConfig
from curve_vae.training.losses import vae_loss
from curve_vae.training.model import VAE
from curve_vae.training.train import train, train_one_epoch


def _curves(n: int, seed: int = 0) -> torch.Tensor:
    g = torch.Generator().manual_seed(seed)
    t = torch.linspace(0, 1, 161)
    a = torch.rand(n, 1, 2, generator=g) * 40 + 10
    return torch.stack([64 + a[..., 0] * torch.cos(3 * t), 64 + a[..., 1] * torch.sin(2 * t)], dim=-1)


def test_only_the_encoders_weights_move_and_every_batchnorm_statistic_stays():
    torch.manual_seed(0)
    model = VAE(ModelConfig(variant="cnn1", spline_ctrl=31))
    trained = model.learn_only_encoder()
    before = {k: v.clone() for k, v in model.state_dict().items()}
    opt = torch.optim.Adam(trained, lr=1e-2)
    cfg = TrainConfig(only_encoder=True, batch_size=16, beta=0.0)
    train_one_epoch(model, _curves(64), torch.arange(64), opt, None, cfg, torch.device("cpu"))
    after = model.state_dict()
    changed = {k for k in before if not torch.equal(before[k], after[k])}
    assert changed, "the encoder did not learn"
    assert all(k.startswith("encoder.") for k in changed), sorted(changed)
    assert not any(k.endswith(("running_mean", "running_var", "num_batches_tracked")) for k in changed)


def test_the_encoder_is_trained_on_the_mean_decoded_as_the_service_decodes_it():
    torch.manual_seed(0)
    model = VAE(ModelConfig(variant="cnn1", spline_ctrl=31))
    model.learn_only_encoder()
    x = _curves(32, seed=1)
    with torch.no_grad():
        pred, mean, log_var = model.eval()(x)
        want = vae_loss(x, pred, mean, log_var, beta=0.0)["mse"]
    opt = torch.optim.SGD([p for p in model.parameters() if p.requires_grad], lr=0.0)  # measure, do not move
    got = train_one_epoch(model, x, torch.arange(32), opt, None, TrainConfig(only_encoder=True, batch_size=32), "cpu")
    assert got["mse"] == pytest.approx(float(want), rel=1e-5)  # sampling z = μ + σ·ε would not match it
    # trained as a whole VAE, the same weights decode a sample z = μ + σ·ε instead
    sampled = train_one_epoch(model, x, torch.arange(32), opt, None, TrainConfig(batch_size=32), "cpu")
    assert sampled["mse"] != pytest.approx(float(want), rel=1e-5)


@pytest.mark.slow
def test_a_run_with_only_encoder_keeps_the_starting_decoder(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    torch.manual_seed(0)
    cfg = ModelConfig(spline_ctrl=31)
    start = tmp_path / "start.pt"
    torch.save({"model_config": cfg.__dict__, "model": VAE(cfg).state_dict()}, start)
    tiny = ["--n-train", "128", "--n-val", "32", "--n-test", "32", "--epochs", "1", "--batch-size", "64"]
    tiny += ["--no-figures"]
    assert main(["train", "--run-dir", "enc", "--init-from", str(start), "--only-encoder", *tiny, "--no-progress"]) == 0
    was, now = torch.load(start)["model"], load_checkpoint(tmp_path / "enc" / "last.pt")["model"]
    assert all(torch.equal(was[k], now[k]) for k in was if not k.startswith("encoder."))
    assert any(not torch.equal(was[k], now[k]) for k in was if k.startswith("encoder."))


def test_match_twin_reconstructs_each_curve_as_its_twin_and_closest_measures_shapes():
    from curve_vae.training.losses import closest_point_terms

    torch.manual_seed(0)
    model = VAE(ModelConfig(variant="cnn1", spline_ctrl=31)).eval()
    model.learn_only_encoder()  # decoded from the mean: the terms are exactly those of the model as it is
    x, twin = _curves(16, seed=2), _curves(16, seed=3)
    opt = torch.optim.SGD([p for p in model.parameters() if p.requires_grad], lr=0.0)
    with torch.no_grad():
        pred, mean, log_var = model(x)
        want_twin = vae_loss(twin, pred, mean, log_var, beta=0.0)["mse"]
        dense = model(x, dense=True)[0]
        want_closest = closest_point_terms(x, dense)["mse"]
    pairs = torch.stack([x, twin], dim=1)
    cfg = TrainConfig(match="twin", only_encoder=True, batch_size=16)
    got = train_one_epoch(model, pairs, torch.arange(16), opt, None, cfg, "cpu")
    assert got["mse"] == pytest.approx(float(want_twin), rel=1e-5)  # the twin is the target, not the input
    cfg = TrainConfig(match="closest", only_encoder=True, batch_size=16)
    got = train_one_epoch(model, x, torch.arange(16), opt, None, cfg, "cpu")
    assert got["mse"] == pytest.approx(float(want_closest), rel=1e-5)
    assert dense.shape == (16, 321, 2)
    with pytest.raises(ValueError, match="match must be one of"):
        TrainConfig(match="nearest")


def test_match_mixed_measures_curves_at_their_own_spacing_by_index_and_the_rest_by_their_shape():
    from curve_vae.training.losses import closest_point_terms, laplacian

    torch.manual_seed(0)
    model = VAE(ModelConfig(variant="cnn1", spline_ctrl=31)).eval()
    model.learn_only_encoder()
    x, other = _curves(16, seed=4), _curves(16, seed=5)
    native = torch.arange(16) < 6  # the first six are their own twins; the rest were drawn at another spacing
    twin = torch.where(native.view(-1, 1, 1), x, other)
    with torch.no_grad():
        pred = model(x)[0]
        dense = model(x, dense=True)[0]
        np.testing.assert_allclose(dense[:, ::2].numpy(), pred.numpy(), atol=1e-3)  # every other sample is a point
        index = (x - pred).square().mean((1, 2))
        lap = (laplacian(x) - laplacian(pred)).abs().mean((1, 2))
        close = closest_point_terms(x, dense, per_curve=True)
    want_mse = (index[:6].sum() + close["mse"][6:].sum()) / 16
    opt = torch.optim.SGD([p for p in model.parameters() if p.requires_grad], lr=0.0)
    cfg = TrainConfig(match="mixed", only_encoder=True, batch_size=16, beta=0.0)
    got = train_one_epoch(model, torch.stack([x, twin], dim=1), torch.arange(16), opt, None, cfg, "cpu")
    assert got["mse"] == pytest.approx(float(want_mse), rel=1e-4)
    assert got["lap"] == pytest.approx(float(lap[:6].sum() / 16), rel=1e-4)  # the Laplacian of matched points only
    assert got["back"] == pytest.approx(float(close["back"][6:].sum() / 16), rel=1e-4)
    assert got["native"] == pytest.approx(6 / 16)
    assert got["loss"] == pytest.approx(got["mse"] + got["lap"] + got["back"], rel=1e-5)


def test_match_mixed_refuses_a_model_whose_points_are_not_at_even_parameters(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    torch.manual_seed(0)
    cfg = ModelConfig(spline_ctrl=31, spline_params=True)
    start = tmp_path / "start.pt"
    torch.save({"model_config": cfg.__dict__, "model": VAE(cfg).state_dict()}, start)
    tiny = ["--n-train", "64", "--n-val", "16", "--n-test", "16", "--epochs", "1", "--batch-size", "32"]
    args = ["--run-dir", "mx", "--init-from", str(start), "--match", "mixed", "--mix", "broad", *tiny, "--no-progress"]
    assert main(["train", *args]) != 0
    assert 'match "mixed" needs the B-spline head at even parameters' in capsys.readouterr().err


@pytest.mark.parametrize("match", ["closest", "twin", "mixed"])
def test_a_match_on_the_decoded_spline_without_the_head_is_refused_before_anything_is_drawn(tmp_path, match):
    cache = tmp_path / "curves.npz"
    data = DataConfig(n_train=64, n_val=16, n_test=16)
    with pytest.raises(ValueError, match=f"match '{match}' measures the decoded spline: it needs the B-spline head"):
        train(tmp_path / "run", ModelConfig(variant="cnn1"), data, TrainConfig(match=match), data_cache=cache)
    assert not cache.exists() and not (tmp_path / "run").exists()


def test_fewer_training_curves_than_one_batch_are_refused_before_any_file_of_the_run(tmp_path):
    data = DataConfig(n_train=48, n_val=16, n_test=16)
    cfg = TrainConfig(batch_size=64, epochs=1)
    with pytest.raises(ValueError, match="48 training curves are fewer than one batch of 64"):
        train(tmp_path / "run", ModelConfig(variant="cnn1"), data, cfg, data_cache=tmp_path / "d.npz", progress=False)
    assert not (tmp_path / "run").exists()


def test_a_pass_drops_the_ragged_last_batch_and_counts_its_steps():
    torch.manual_seed(0)
    model = VAE(ModelConfig(variant="cnn1"))
    opt = torch.optim.SGD(model.parameters(), lr=0.0)
    got = train_one_epoch(model, _curves(50), torch.arange(50), opt, None, TrainConfig(batch_size=16), "cpu")
    assert got["steps"] == 3  # 50 curves: three full batches of 16, the last 2 curves left out
    assert got["loss"] == pytest.approx(got["mse"] + 1e-3 * got["kl"] + got["lap"], rel=1e-5)  # beta 1e-3, lap 1


@pytest.mark.slow
def test_sigkill_mid_epoch_then_resume(tmp_path):
    """A training run killed with SIGKILL mid-epoch resumes from its last checkpoint, losing at most that epoch."""
    run, data = tmp_path / "run", str(tmp_path / "curves.npz")
    args = [sys.executable, "-m", "curve_vae.cli", "train", "--run-dir", str(run), "--data", data, "--epochs", "2",
            "--n-train", "256", "--n-val", "32", "--n-test", "32", "--batch-size", "64", "--threads", "1",
            "--no-progress", "--no-figures", "--resume"]  # fmt: skip
    proc = subprocess.Popen(args, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, env=os.environ)
    log = run / "log.jsonl"
    deadline = time.monotonic() + 120
    while not (log.exists() and log.read_text().count("\n") >= 1):  # epoch 1 done and saved ...
        assert proc.poll() is None and time.monotonic() < deadline, proc.stdout.read()  # type: ignore[union-attr]
        time.sleep(0.05)
    time.sleep(0.3)  # ... and epoch 2 under way
    proc.send_signal(signal.SIGKILL)
    proc.wait(timeout=30)
    proc.stdout.close()  # type: ignore[union-attr]
    assert proc.returncode == -signal.SIGKILL
    done = load_checkpoint(run / "last.pt")["state"]["epoch"]  # the checkpoint on disk is whole
    logged = log.read_text().count("\n")
    assert done >= 1 and done == logged  # the checkpoint and the log agree on the epochs completed
    again = subprocess.run(args, capture_output=True, text=True, timeout=300)
    assert again.returncode == 0, again.stdout + again.stderr
    assert f"resumed {run / 'last.pt'} at epoch {done}/2" in again.stdout
    rows = [json.loads(line) for line in log.read_text().splitlines()]
    assert [r["epoch"] for r in rows] == [1, 2]  # nothing lost but the killed epoch, nothing repeated
    assert not list(run.glob("*.tmp")) and not list(run.glob(".*.tmp"))  # no half-written checkpoint left
