"""Batch runner: every back end gives bit-identical results to single runs, in input order."""
from __future__ import annotations

import math

import numpy as np
import pytest

from auvtrack.scenario import load_scenario
from auvtrack.simulation.pipeline import prepare, run_prepared
from auvtrack.batch.runner import RunSummary, iter_batch, run_batch, run_metrics
from auvtrack.metrics import METRIC_NAMES
from auvtrack.scenario import paper_scenario_path

PAPER = paper_scenario_path()

# a mix of controllers, envelopes, estimators, sampled-data control and failures
CASES = [
    {"controller.kind": "ftsmc", "sim.duration": 0.4},
    {"controller.kind": "fxtntsmc", "sim.duration": 0.4},
    {"controller.kind": "fxtntsmc", "sim.duration": 0.3, "envelope.kind": "reactive", "estimator.kind": "printed",
     "seed": 7},
    {"controller.kind": "fxtntsmc", "sim.duration": 0.3, "envelope.kind": "none", "estimator.kind": "none"},
    {"controller.kind": "ftsmc", "sim.duration": 0.4, "sim.control_rate": 100.0, "uncertainty.M": 0.2},
    {"controller.kind": "open_loop", "sim.duration": 0.2},
    {"controller.kind": "ftsmc", "sim.duration": 0.4, "sim.theta_limit": 0.01},  # fails: pitch limit
    {"controller.kind": "fxtntsmc", "sim.duration": 0.4, "envelope.kind": "rigid", "envelope.widen_start": True,
     "envelope.xi0": 0.999, "envelope.lambda1": 50.0, "uncertainty.D": 1.5},
]


@pytest.fixture(scope="module")
def preps():
    return [prepare(load_scenario(PAPER, case)) for case in CASES]


@pytest.fixture(scope="module")
def singles(preps):
    return [run_prepared(p) for p in preps]


def _metrics_array(m: dict) -> np.ndarray:
    return np.array([m[k] for k in METRIC_NAMES])


def assert_same(summary: RunSummary, res) -> None:
    """Bit-identical status, failure and metrics (NaN == NaN)."""
    assert summary.status == res.status
    assert summary.failure == res.failure
    np.testing.assert_array_equal(_metrics_array(summary.metrics), _metrics_array(res.metrics))
    assert set(summary.metrics) == set(res.metrics)


def test_cases_cover_success_and_failure(singles):
    statuses = {r.status for r in singles}
    assert statuses == {"ok", "failed"}, statuses
    assert singles[6].failure["cause"] == "pitch_limit"


@pytest.mark.parametrize("backend", ["serial", "threads", "prange", "simd"])
def test_batch_equals_single_runs_bitwise(preps, singles, backend):
    out = run_batch(preps, backend=backend, workers=2)
    assert len(out) == len(preps)
    for s, r in zip(out, singles):
        assert_same(s, r)


def test_batch_shuffled_order_and_repeats(preps, singles):
    order = [5, 1, 1, 7, 0, 3, 2, 6, 4, 1]
    out = run_batch([preps[i] for i in order], backend="threads", workers=2)
    for s, i in zip(out, order):
        assert_same(s, singles[i])


def test_batch_trajectories_equal_single_runs(preps, singles):
    out = run_batch(preps[:4], trajectories=True, workers=2)
    for res, ref in zip(out, singles):
        assert res.status == ref.status
        assert list(res.channels) == list(ref.channels)
        for name in ref.channels:
            np.testing.assert_array_equal(res.channels[name], ref.channels[name])


def test_metrics_only_run_keeps_no_trajectory(preps, singles):
    s = run_metrics(preps[1])
    assert_same(s, singles[1])
    assert s.steps == int(round(0.4 / 0.001)) and math.isclose(s.t_stop, 0.4)


def test_iter_batch_streams_in_order(preps, singles):
    got = list(iter_batch(range(len(preps)), lambda i: preps[i], block=3, workers=2))
    assert [i for i, _ in got] == list(range(len(preps)))
    for i, s in got:
        assert_same(s, singles[i])


def test_bad_arguments():
    with pytest.raises(ValueError, match="backend"):
        run_batch([], backend="gpu")
    with pytest.raises(ValueError, match="workers"):
        run_batch([], workers=0)
    with pytest.raises(ValueError, match="block"):
        list(iter_batch([1], lambda i: i, block=0))


def test_stage_reuse_of_reference_and_disturbance_is_exact(preps):
    """The engine reuses stage 2's reference and omega at stage 3 (same time): same numbers as fresh."""
    from auvtrack.control.contract import WORK_SIZE, LawOutputs
    from auvtrack.environment.layout import KIND_CURRENT
    from auvtrack.plant.contract import SCRATCH_SIZE
    from auvtrack.vehicle.kinematics import attitude
    from auvtrack.engine import loop as engine
    from auvtrack.engine import kernels

    p = preps[0]  # ftsmc, paper disturbance
    rows0 = p.environment.rows
    assert engine.state_free_disturbance(rows0)
    rows = rows0.copy()
    rows[0, 0] = KIND_CURRENT
    assert not engine.state_free_disturbance(rows)
    stage = kernels.kernel_module(p.key).stage
    t, nxp, nxc = 0.3705, p.plant.x0.size, p.controller.x0.size

    def call(xp, fresh, sk):
        refm, scr = sk
        dxp, dxc, tau, aux = np.zeros(nxp), np.zeros(nxc), np.zeros(3), np.zeros(3)
        lp = engine.Loop(p.pp, p.cp, p.vp_nom, p.ref_p, rows0, p.environment.current, 0, 0.0)
        buf = engine.Buffers(refm, np.zeros(WORK_SIZE), scr, np.zeros(3))
        st, _ = stage(t, xp, p.controller.x0, attitude(xp[3], xp[4]), lp, buf, dxp, LawOutputs(tau, dxc, aux), fresh)
        assert st == 0
        return dxp, tau

    def scratch():
        return np.zeros((3, 3)), np.zeros(SCRATCH_SIZE)

    xa, xb = p.plant.x0 + 0.01, p.plant.x0 - 0.02
    sk = scratch()
    call(xa, True, sk)
    reused = call(xb, False, sk)
    fresh = call(xb, True, scratch())
    np.testing.assert_array_equal(reused[0], fresh[0])
    np.testing.assert_array_equal(reused[1], fresh[1])


def test_state_check_precedence(preps):
    """One-pass state check over plant and controller states: non-finite before pitch before state limit."""
    from auvtrack.engine import loop as engine
    from auvtrack.engine import kernels
    from auvtrack.plant.contract import SF

    state_cause = kernels.kernel_module(preps[0].key).state_cause
    sf = np.zeros(SF.size)
    sf[SF.theta_lim], sf[SF.state_lim] = 1.0, 10.0
    xp, xc = np.zeros(10), np.zeros(2)
    assert state_cause(xp, xc, sf) == engine.CAUSE_NONE
    xp[3], xp[7] = 2.0, 50.0
    assert state_cause(xp, xc, sf) == engine.CAUSE_PITCH
    xc[1] = np.inf
    assert state_cause(xp, xc, sf) == engine.CAUSE_NONFINITE
    xp[3], xc[1] = 0.5, 0.0
    assert state_cause(xp, xc, sf) == engine.CAUSE_STATE_LIMIT
    xp[7], xc[0] = 0.0, -11.0
    assert state_cause(xp, xc, sf) == engine.CAUSE_STATE_LIMIT
