"""Sweep summaries never pool different controllers: quantiles per group of named grid values."""
from __future__ import annotations

import textwrap
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest

from auvtrack.batch.sweep import QUANTILES, group_keys, summarize, summary_markdown
from auvtrack.batch.sweep_spec import load_study
from auvtrack.batch.sweep_worker import run_chunk

ROOT = Path(__file__).resolve().parents[2]
STUDY = """
name = "g"
scenario = "paper"
set = ["sim.duration=0.3", "estimator.neurons=3"]
seed = 5
samples = 6
chunk_size = 8

[grid]
"controller.kind" = ["ftsmc", "fxtntsmc"]
"uncertainty.C" = [0.0, 0.2]

[random."disturbance.0.amplitude"]
dist = "loguniform"
low = 0.5
high = 2.0
"""


@pytest.fixture(scope="module")
def results(tmp_path_factory):
    folder = tmp_path_factory.mktemp("groups")
    (folder / "study.toml").write_text(textwrap.dedent(STUDY))
    spec = load_study(folder / "study.toml")
    table = pa.concat_tables([run_chunk(spec, c) for c in range(spec.n_chunks)])
    pq.write_table(table, folder / "results.parquet")
    return spec, table.to_pandas(), summarize(folder / "results.parquet", spec)


def test_groups_are_the_named_grid_keys():
    assert group_keys(load_study(ROOT / "scenarios" / "sweep_example.toml")) == ["controller.kind"]


def test_each_group_holds_exactly_its_own_samples(results):
    spec, df, s = results
    assert s["group_keys"] == ["controller.kind"]  # the numeric grid key uncertainty.C is not a group
    assert [g["key"] for g in s["groups"]] == [{"controller.kind": "ftsmc"}, {"controller.kind": "fxtntsmc"}]
    assert sum(g["samples"] for g in s["groups"]) == s["samples"] == len(df)
    for g in s["groups"]:
        rows = df[df["controller.kind"] == g["key"]["controller.kind"]]
        assert g["samples"] == len(rows) == 12
        ok = rows[rows["status"] == "ok"]
        assert g["counts"].get("ok", 0) == len(ok)
        for m in ("rmse_x", "tv_tau_u"):
            vals = ok[m].to_numpy()
            vals = vals[np.isfinite(vals)]
            assert g["metrics"][m]["n_finite"] == vals.size
            np.testing.assert_array_equal([g["metrics"][m][f"q{int(round(q * 100)):02d}"] for q in QUANTILES],
                                          np.quantile(vals, QUANTILES))
    # the controllers really differ, so pooling them would describe neither
    med = [g["metrics"]["tv_tau_u"]["q50"] for g in s["groups"]]
    assert max(med) > 2 * min(med)


def test_markdown_has_one_quantile_table_per_group(results):
    _, _, s = results
    text = summary_markdown(s)
    assert "## controller.kind = ftsmc" in text and "## controller.kind = fxtntsmc" in text
    assert text.count("| metric | n | inf | mean |") == 2
    ungrouped = {**s, "groups": [], "group_keys": []}
    assert summary_markdown(ungrouped).count("| metric | n | inf | mean |") == 1
