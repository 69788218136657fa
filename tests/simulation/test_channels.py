"""Renamed channels (sliding_*, zeta_*): the old names stay readable for one release."""
from __future__ import annotations

import warnings

import numpy as np
import pytest

from auvtrack.control import ftsmc, fxtntsmc
from auvtrack.simulation.channels import LEGACY_NAMES, current_name, legacy_columns, upgrade_names
from auvtrack.simulation.result import Result

from test_result import make_result


def test_both_controllers_log_the_same_unambiguous_names():
    assert ftsmc.AUX_NAMES == ("sliding_x", "sliding_y", "sliding_z")
    assert {f"sliding_{a}" for a in "xyz"} | {f"zeta_{a}" for a in "xyz"} <= set(fxtntsmc.AUX_NAMES)
    # no aux channel can be mistaken for a state channel (the old z_x sat beside the position z)
    for name in ftsmc.AUX_NAMES + fxtntsmc.AUX_NAMES:
        assert name.split("_")[0] not in ("x", "y", "z", "s", "S"), name
    # every old name maps onto a channel the controller really logs
    assert set(LEGACY_NAMES["fxtntsmc"].values()) <= set(fxtntsmc.AUX_NAMES)
    assert set(LEGACY_NAMES["ftsmc"].values()) <= set(ftsmc.AUX_NAMES)


def test_old_name_reads_the_new_channel_with_a_future_warning():
    res = make_result()
    with pytest.warns(FutureWarning, match="'S_x' is deprecated.*'sliding_x'"):
        old = res["S_x"]
    assert old is res["sliding_x"]
    assert "S_x" in res and "sliding_x" in res
    # another controller's old name is not invented for this one
    assert "s_x" not in res
    with pytest.raises(KeyError):
        res["s_x"]
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        res["sliding_x"]  # the new name never warns


def test_ftsmc_old_name_and_unknown_kind():
    ft = make_result(kind="ftsmc")
    with pytest.warns(FutureWarning):
        np.testing.assert_array_equal(ft["s_z"], ft["sliding_z"])
    assert "S_x" not in ft
    assert current_name("S_x", ["sliding_x"], None, warn=False) == "sliding_x"  # unknown kind: any old name
    assert legacy_columns(["sliding_x"], None) == {}  # ...but no old column is invented


def test_run_folder_written_with_old_names_loads_under_the_new_ones(tmp_path):
    res = make_result()
    ch = {("S_" + k[len("sliding_"):] if k.startswith("sliding_") else k): v for k, v in res.channels.items()}
    old = Result(ch, res.scenario, "ok", None, res.metrics)
    back = Result.load(old.save(tmp_path / "old"))
    assert back.names == res.names
    np.testing.assert_array_equal(back["sliding_y"], res["sliding_y"])


def test_upgrade_keeps_new_names_and_unrelated_columns():
    assert upgrade_names(["t", "z", "z_x", "S_y", "s_z"], "fxtntsmc") == ["t", "z", "zeta_x", "sliding_y", "s_z"]
    assert upgrade_names(["s_x", "sliding_x"], "ftsmc") == ["s_x", "sliding_x"]  # never two equal names
