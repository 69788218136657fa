"""``metrics.path = false`` skips the projection on the path and nothing else.

The path-following metrics are then NaN; every other metric, the status and the trajectory are
bit for bit those of the same run with the projection (the projection only feeds those metrics),
on the single-run kernel and in the lanes of the SIMD batch.
"""
from __future__ import annotations

import math

import numpy as np
import pytest

from auvtrack.batch.runner import run_batch, run_metrics
from auvtrack.metrics import PATH_NAMES
from auvtrack.scenario import load_scenario, paper_scenario_path
from auvtrack.simulation.pipeline import prepare, run_prepared

PATH_METRICS = set(PATH_NAMES) | {f"{k}_late" for k in PATH_NAMES}
BASE = {"sim.duration": 1.0, "sim.log_dt": 0.01}


def _same(a: float, b: float) -> bool:
    return a == b or (math.isnan(a) and math.isnan(b))


def test_without_path_metrics_only_they_change():
    on = run_prepared(prepare(load_scenario(paper_scenario_path(), BASE)))
    off = run_prepared(prepare(load_scenario(paper_scenario_path(), {**BASE, "metrics.path": False})))
    assert on.status == off.status == "ok"
    assert all(math.isfinite(on.metrics[k]) for k in PATH_METRICS)
    assert all(math.isnan(off.metrics[k]) for k in PATH_METRICS)
    others = [k for k in on.metrics if k not in PATH_METRICS]
    assert [k for k in others if not _same(on.metrics[k], off.metrics[k])] == []
    for name in on.names:
        assert np.array_equal(on[name], off[name], equal_nan=True), name


@pytest.mark.slow
def test_the_simd_lanes_follow_the_switch_run_by_run():
    """A SIMD batch mixing runs with and without the path metrics gives each run its single-run metrics."""
    preps = [prepare(load_scenario(paper_scenario_path(), {**BASE, "seed": i, "metrics.path": i % 2 == 0}))
             for i in range(8)]
    batch = run_batch(preps, backend="simd", workers=1)
    for p, b in zip(preps, batch):
        single = run_metrics(p).metrics
        assert all(_same(single[k], b.metrics[k]) for k in single)
        assert math.isnan(b.metrics["xtrack_rmse"]) == (not p.scenario.metrics.path)
