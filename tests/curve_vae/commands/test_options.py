"""curve_vae/commands/options.py: the options several commands share, through the commands that take them. The
reading flags are Reading's fields (values, default, bounds) and are checked before any file is read; the data set's
options are checked before any curve is drawn."""

import pytest

from curve_vae.cli import main
from curve_vae.inference.reading import Reading, reading_options

TINY = ["--n-train", "96", "--n-val", "16", "--n-test", "16", "--epochs", "1", "--no-progress", "--batch-size", "32"]
READING_COMMANDS = ["reconstruct", "encode", "augment"]


def test_mix_version_goes_with_the_broad_mix_only(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    assert main(["train", "--run-dir", "r", "--mix-version", "2", *TINY]) == 2
    assert "--mix-version goes with --mix broad" in capsys.readouterr().err
    assert not (tmp_path / "r").exists()


def test_mix_version_is_refused_with_own_curves_too_before_they_are_read(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    argv = ["dataset", "--curves", str(tmp_path / "no-such-folder"), "--mix-version", "3", *TINY[:6]]
    assert main(argv) == 2
    assert "--mix-version goes with --mix broad" in capsys.readouterr().err
    assert not (tmp_path / "data").exists()


@pytest.mark.parametrize("command", READING_COMMANDS)
def test_every_reading_value_is_a_flag_value_and_the_defaults_are_readings(command):
    from curve_vae.cli import build_parser

    extra = ["--count", "1"] if command == "augment" else []
    parsed = build_parser().parse_args([command, "in.json", *extra])
    assert Reading(**{o.name: getattr(parsed, o.name) for o in reading_options()}) == Reading()
    for o in reading_options():
        for value in o.values:
            parsed = build_parser().parse_args([command, "in.json", *extra, f"--{o.name}", value])
            assert getattr(parsed, o.name) == value


@pytest.mark.parametrize("command", READING_COMMANDS)
@pytest.mark.parametrize(
    "flag,value",
    [pytest.param("--pose", "sideways", id="pose"), pytest.param("--spacing", "random", id="spacing")],
)
def test_a_reading_value_outside_its_choices_is_a_usage_error(command, flag, value, capsys):
    with pytest.raises(SystemExit) as e:
        main([command, "in.json", flag, value])
    assert e.value.code == 2
    assert f"invalid choice: '{value}'" in capsys.readouterr().err


@pytest.mark.parametrize("command", READING_COMMANDS)
@pytest.mark.parametrize("refine", ["-1", "31"], ids=["negative", "past-the-most"])
def test_an_out_of_range_refine_is_named_before_the_curves_are_read(command, refine, tmp_path, model_dir, capsys):
    extra = ["--count", "1"] if command == "augment" else []
    missing = tmp_path / "never-read.json"  # were the file read first, the error would name it
    out = tmp_path / "out.json"
    argv = [command, str(missing), *extra, "--refine", refine, "--model-dir", str(model_dir), "-o", str(out)]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert "refine" in err and f"got {refine}" in err and "never-read" not in err, err
    assert not out.exists()


def test_the_model_dir_names_what_is_missing(tmp_path, capsys):
    argv = ["encode", str(tmp_path / "c.json"), "--model-dir", str(tmp_path), "-o", str(tmp_path / "e.json")]
    (tmp_path / "c.json").write_text("[[[0, 0], [1, 1], [2, 0], [3, 1]]]")
    assert main(argv) == 2
    assert "manifest.json is missing" in capsys.readouterr().err
    assert not (tmp_path / "e.json").exists()
