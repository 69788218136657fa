"""The run plan: every size-setting field is bounded by the documented [limits] before anything is
allocated, check and run refuse it with the same line, and the sizes and memory estimate are right."""
from __future__ import annotations

import contextlib
import io
import tracemalloc
import warnings
from pathlib import Path
from unittest import mock

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from auvtrack.cli import EXIT_BAD_INPUT, main
from auvtrack.scenario import ScenarioError, load_scenario
from auvtrack.scenario.plan import plan_run
from auvtrack.simulation.pipeline import prepare, run_prepared
from doc_ranges import limits_defaults

ROOT = Path(__file__).resolve().parents[2]
PAPER = ROOT / "scenarios" / "paper.toml"
LIM = limits_defaults()  # the documented defaults, not the schema's
CH = 41  # channels of the fxtntsmc log (20 base, 18 controller, 3 chi)
NOISE = ["sensor.sigma_eta=[0.01, 0, 0, 0, 0]"]


def test_the_documented_defaults_are_the_defaults():
    assert load_scenario({}).limits.model_dump() == LIM


# each case: overrides exceeding one documented limit, the field it must name, the limit key
OVER = [
    ([f"sim.duration={2 * LIM['max_steps'] * 1e-3:.17g}"], "sim.duration", "max_steps"),
    ([f"sim.dt={100 / (2 * LIM['max_steps']):.17g}"], "sim.dt", "max_steps"),
    ([f"sim.duration={2 * LIM['max_log_rows'] * 1e-3:.17g}", "sim.log_dt=0.001"], "sim.log_dt", "max_log_rows"),
    ([f"sim.duration={1.5 * LIM['max_table_rows'] * 1e-4:.17g}", "sim.dt=0.0001", "sim.control_rate=10000", *NOISE],
     "sim.control_rate", "max_table_rows"),
    ([f"disturbance.0.kind=current", f"disturbance.0.sample_dt={100 / (2 * LIM['max_table_rows']):.17g}"],
     "disturbance.0.sample_dt", "max_table_rows"),
    # within the row limits, over the memory limit: the largest share is named
    ([f"sim.duration=10000", "sim.log_dt=0.002"], "sim.log_dt", "max_memory_mb"),
    ([f"disturbance.1.kind=current", f"disturbance.1.sample_dt={100 / (0.95 * LIM['max_table_rows']):.17g}"],
     "disturbance.1.sample_dt", "max_memory_mb"),
]


class _Ran(Exception):
    pass


def _cli(args):
    err = io.StringIO()
    with mock.patch("auvtrack.simulation.pipeline.run_prepared", side_effect=_Ran), \
            contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
        code = main(args)
    return code, err.getvalue().strip()


@pytest.mark.parametrize("overrides, field, key", OVER, ids=[f"{f}-{k}" for _, f, k in OVER])
def test_a_run_over_a_limit_is_one_line_from_check_and_run(tmp_path, overrides, field, key):
    sets = [a for ov in overrides for a in ("--set", ov)]
    check = _cli(["check", str(PAPER), *sets])
    run = _cli(["run", str(PAPER), "--out", str(tmp_path / "out"), *sets])
    assert check == run, (check, run)
    code, line = check
    assert code == EXIT_BAD_INPUT and len(line.splitlines()) == 1, line
    assert line.startswith(f"auvtrack: error: {PAPER}: {field}: "), line
    assert f"more than limits.{key} = {LIM[key]}" in line and "Traceback" not in line
    assert not (tmp_path / "out").exists()  # refused before anything was written
    # raising that limit deliberately removes this refusal (another limit may then bind), and
    # raising them all lets the plan through (checked on the plan alone: nothing is allocated)
    ceiling = {"max_steps": 2 ** 53, "max_log_rows": 2 ** 40, "max_table_rows": 2 ** 31, "max_memory_mb": 2 ** 30}
    try:
        plan_run(load_scenario(PAPER, overrides + [f"limits.{key}={ceiling[key]}"]), CH)
    except ScenarioError as exc:
        assert f"limits.{key} " not in str(exc), exc
    plan_run(load_scenario(PAPER, overrides + [f"limits.{k}={v}" for k, v in ceiling.items()]), CH)


def test_too_many_neurons_is_refused_by_check_as_by_run(tmp_path):
    sets = ["--set", "estimator.neurons=513"]
    check, run = _cli(["check", str(PAPER), *sets]), _cli(["run", str(PAPER), "--out", str(tmp_path / "o"), *sets])
    assert check == run and check[0] == EXIT_BAD_INPUT and "estimator.neurons: at most 512" in check[1]


def test_a_start_on_the_envelope_without_widening_is_refused_by_check_as_by_run(tmp_path):
    sets = ["--set", "envelope.widen_start=false"]
    check, run = _cli(["check", str(PAPER), *sets]), _cli(["run", str(PAPER), "--out", str(tmp_path / "o"), *sets])
    assert check == run and check[0] == EXIT_BAD_INPUT and "widen_start" in check[1]


SIZES = st.floats(min_value=5e-324, max_value=1.7e308, allow_nan=False, allow_infinity=False)


@settings(max_examples=300, deadline=None)
@given(duration=SIZES, dt=SIZES, log_every=st.integers(1, 10**9), rate=SIZES, sample_dt=SIZES,
       noisy=st.booleans())
def test_every_size_is_bounded_before_it_becomes_an_integer(duration, dt, log_every, rate, sample_dt, noisy):
    """Any numbers at all: loading and planning end in a plan within the limits or one
    ScenarioError, never an OverflowError or a NumPy allocation error."""
    raw = {"sim": {"duration": duration, "dt": min(dt, 0.1), "log_dt": log_every * min(dt, 0.1),
                   "control_rate": rate},
           "disturbance": [{"kind": "current", "sample_dt": sample_dt}],
           "sensor": {"sigma_eta": [0.01 if noisy else 0.0, 0, 0, 0, 0]}}
    try:
        sc = load_scenario(raw)
        plan = plan_run(sc, CH)
    except ScenarioError as exc:
        assert "\n" not in str(exc)
        return
    lim = sc.limits
    assert plan.n_steps <= lim.max_steps and plan.log_rows <= lim.max_log_rows
    assert plan.noise_rows <= lim.max_table_rows and max(plan.current_rows) <= lim.max_table_rows
    assert plan.memory_bytes <= lim.max_memory_mb * 2 ** 20


@pytest.mark.parametrize("overrides", [
    [],
    ["sim.control_rate=100", *NOISE, "sim.log_dt=0.05"],
    ["controller.kind=ftsmc", "disturbance.1.kind=current", "disturbance.1.sample_dt=0.003",
     "disturbance.2.kind=current", "sim.duration=7"],
])
def test_the_plan_is_what_prepare_allocates(overrides):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        sc = load_scenario(PAPER, ["sim.duration=3", *overrides])
        prep = prepare(sc)
    plan = plan_run(sc, len(prep.channels))
    assert plan.n_steps == round(sc.sim.duration / sc.sim.dt) == prep.si[0]
    assert plan.log_rows == prep.n_rows == round(sc.sim.duration / sc.sim.log_dt) + 1
    assert plan.noise_rows == prep.noise.shape[0]
    assert sum(plan.current_rows) == (prep.environment.current.shape[0] if plan.current_rows else 0)
    res = run_prepared(prep)
    assert len(res) == plan.log_rows and res.t[-1] == pytest.approx(sc.sim.duration)  # the log ends at the end


MEMORY_CASES = {
    "log, noise and two currents": ["sim.duration=20", "sim.dt=0.0005", "sim.log_dt=0.0005", "sim.control_rate=2000",
                                    *NOISE, "disturbance.1.kind=current", "disturbance.1.sample_dt=0.00005",
                                    "disturbance.2.kind=current", "disturbance.2.sample_dt=0.0001",
                                    "controller.kind=ftsmc"],
    "log": ["sim.duration=50", "sim.log_dt=0.001"],
    "current": ["sim.duration=10", "disturbance.1.kind=current", "disturbance.1.sample_dt=0.00001", "sim.log_dt=1"],
    "noise": ["sim.duration=20", "sim.control_rate=1000", *NOISE, "sim.log_dt=1", "controller.kind=ftsmc"],
}


@pytest.mark.parametrize("case", list(MEMORY_CASES))
def test_the_memory_estimate_bounds_the_traced_peak(tmp_path, case):
    """prepare + run + save: the estimate is above the peak of the NumPy/Python allocations traced,
    and within a factor 2.5 of it (the parts' peaks, summed by the estimate, do not coincide)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        sc = load_scenario(PAPER, MEMORY_CASES[case])
        for kind in ("ftsmc", "fxtntsmc"):  # load the kernels first: their set-up is not the run's
            run_prepared(prepare(load_scenario(PAPER, ["sim.duration=0.01", f"controller.kind={kind}"])))
        tracemalloc.start()
        try:
            prep = prepare(sc)
            res = run_prepared(prep)
            res.save(tmp_path / "run")
            _, peak = tracemalloc.get_traced_memory()
        finally:
            tracemalloc.stop()
    plan = plan_run(sc, len(prep.channels))
    assert res.ok and plan.log_rows == len(res) and plan.noise_rows == prep.noise.shape[0]
    assert peak <= plan.memory_bytes <= 2.5 * peak, (peak, plan.memory_bytes)
