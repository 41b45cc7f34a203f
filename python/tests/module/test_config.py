"""Run files from Python: dict, TOML text and path give the same run; info() is `mresim info`."""

import json

import numpy as np
import pytest

import mresim
from conftest import PAIR_DICT, PAIR_TOML


def test_dict_and_toml_text_describe_the_same_run():
    from_dict = mresim.Run(PAIR_DICT)
    from_text = mresim.Run(PAIR_TOML)
    assert from_dict.run_type == from_text.run_type == "pair_hysteresis"
    assert from_dict.config == from_text.config
    info_dict, info_text = from_dict.info(), from_text.info()
    assert info_dict["run"].pop("file")["value"] == "<dict>"
    assert info_text["run"].pop("file")["value"] == "<string>"
    assert info_dict == info_text


def test_dict_and_toml_text_compute_the_same_results():
    a = mresim.run(PAIR_DICT).cases[0]
    b = mresim.run(PAIR_TOML).cases[0]
    for name in ("field", "distance", "magnetization_along_field"):
        np.testing.assert_array_equal(a[name], b[name])
    np.testing.assert_array_equal(a["energy"]["total"], b["energy"]["total"])


def test_info_is_the_command_line_report(tmp_path, cli_info):
    path = tmp_path / "pair.toml"
    path.write_text(PAIR_TOML)
    assert mresim.info(path) == cli_info(path)
    # Overrides as --set: a list of arguments or a dict.
    assert mresim.info(path, ["field.max=0.25"]) == cli_info(path, "--set", "field.max=0.25")
    assert mresim.info(path, {"field.max": 0.25}) == cli_info(path, "--set", "field.max=0.25")


def test_numpy_values_in_a_dict_are_run_file_values():
    config = json.loads(json.dumps(PAIR_DICT))
    config["springs"]["k"] = np.float64(1e-2)
    config["field"]["max"] = np.array(0.5)
    assert mresim.Run(config).config == mresim.Run(PAIR_DICT).config


def test_run_types_lists_the_command_line_types(cli):
    listed = cli("types").stdout
    types = mresim.run_types()
    assert "pair_hysteresis" in types and "mess_hysteresis" in types
    for name in types:
        assert name in listed


def test_a_plain_string_is_toml_text_not_a_path():
    with pytest.raises(mresim.ConfigError):
        mresim.Run("examples/fig2_2_single_spring_axial.toml")
