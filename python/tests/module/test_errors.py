"""Bad input raises mresim.ConfigError (a ValueError) with the command line's exact message."""

import pytest

import mresim
from conftest import PAIR_TOML


def cli_error(cli, path, *args):
    done = cli("info", path, *args)
    assert done.returncode == 2, done.stderr
    prefix = "mresim: error: "
    assert done.stderr.startswith(prefix)
    return done.stderr[len(prefix):].rstrip("\n")


@pytest.mark.parametrize(
    "bad_toml",
    [
        PAIR_TOML.replace("k = 1e-2", "k = -1e-2"),  # out of range
        PAIR_TOML.replace("step = 0.025", "stpe = 0.025"),  # unknown key
        PAIR_TOML.replace('type = "pair_hysteresis"', 'type = "pair_hysterisis"'),  # bad choice
        PAIR_TOML.replace("max = 0.5", "max = 0.51"),  # not a whole number of steps
        PAIR_TOML.replace("[springs]", "[springs"),  # TOML syntax error: names the file
    ],
)
def test_config_error_message_is_the_command_lines(tmp_path, cli, bad_toml):
    path = tmp_path / "bad.toml"
    path.write_text(bad_toml)
    with pytest.raises(mresim.ConfigError) as raised:
        mresim.Run(path)
    assert str(raised.value) == cli_error(cli, path)
    assert isinstance(raised.value, ValueError)
    assert "\n" not in str(raised.value)


def test_bad_override_message_is_the_command_lines(tmp_path, cli):
    path = tmp_path / "pair.toml"
    path.write_text(PAIR_TOML)
    with pytest.raises(mresim.ConfigError) as raised:
        mresim.info(path, ["field.max=-1"])
    assert str(raised.value) == cli_error(cli, path, "--set", "field.max=-1")


def test_missing_file_message_is_the_command_lines(tmp_path, cli):
    path = tmp_path / "missing.toml"
    with pytest.raises(mresim.ConfigError) as raised:
        mresim.Run(path)
    assert str(raised.value) == cli_error(cli, path)


def test_values_toml_cannot_hold_name_their_key():
    with pytest.raises(mresim.ConfigError, match=r"^field\.max = None: not a run-file value"):
        mresim.Run({"run": {"type": "pair_hysteresis"}, "field": {"max": None}})


def test_refused_output_directory_is_an_os_error(tmp_path):
    occupied = tmp_path / "occupied"
    occupied.mkdir()
    (occupied / "notes.txt").write_text("not mresim's")
    with pytest.raises(mresim.OutputDirectoryError):
        mresim.run(PAIR_TOML, occupied)
    assert (occupied / "notes.txt").read_text() == "not mresim's"


def test_bad_thread_count_names_the_option():
    with pytest.raises(ValueError, match=r"^threads = -1: must be between 0 and"):
        mresim.Run(PAIR_TOML).run(threads=-1)


def test_load_of_a_directory_without_results(tmp_path):
    with pytest.raises(FileNotFoundError, match="not an mresim run directory"):
        mresim.load(tmp_path)
