"""SIMD batch back end: runs in the lanes of one register give the single runs' results.

* the lane rewrite (auvtrack.engine.lanes) on functions exercising each construct: lane by lane
  the scalar function's results, for any inputs (hypothesis);
* every controller's law in lane form against the scalar law at the same states;
* whole runs: metrics to 1e-9 relative (in fact bit for bit, asserted separately), failure cause,
  time and state, steps, for batches with runs that fail at different times, of different lengths,
  of several controllers, sampled-data and continuous;
* a law the rewrite cannot handle, or whose lane form Numba cannot type, runs on the thread back
  end instead, with the same results;
* a stop request reaches every lane.
"""
from __future__ import annotations

import dataclasses
import math
import textwrap

import numba
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import lane_cases
from auvtrack.jit.lane_values import as_lanes, full_mask, get_lane
from auvtrack.batch.runner import StopSignal, _run_simd, run_batch
from auvtrack.simulation.compiling import builtin_controllers
from auvtrack.scenario import load_scenario, paper_scenario_path
from auvtrack.engine import loop as engine
from auvtrack.engine import kernels
from auvtrack.user_modules import load_module
from auvtrack.simulation.pipeline import prepare, run_prepared
from auvtrack.engine.lanes import NotLaneable, lane_source, lane_version
from auvtrack.metrics import METRIC_NAMES

L = engine.LANES
PAPER = paper_scenario_path()


# ------------------------------------------------------------------ the rewrite, construct by construct

N_OUT = {"branches": 2, "loops": 2, "return_in_loop": 2, "maths": 7, "shared": 7}


def _driver(fn, kinds):
    """A compiled function running the lane form of ``fn`` on (n_args, L) inputs, writing (L, n_out)."""
    lane = lane_version(fn)
    n_out = N_OUT[fn.py_func.__name__]
    args = ", ".join(f"Fl[{i}]" if k == "f" else f"Il[{i}]" for i, k in enumerate(kinds))
    stores = "; ".join(f"out[k, {j}] = get_lane(r[{j}], k)" for j in range(n_out))
    src = textwrap.dedent(f"""
        def drive(F, I, out):
            Fl, Il = as_lanes(F, {L}), as_lanes(I, {L})
            r = lane({args}, full_mask({L}))
            for k in range({L}):
                {stores}
    """)
    ns = {"as_lanes": as_lanes, "full_mask": full_mask, "get_lane": get_lane, "lane": lane}
    exec(src, ns)  # noqa: S102
    return numba.njit(ns["drive"]), n_out


_DRIVERS: dict = {}


def _lanes_of(name, F, I):
    fn, kinds = lane_cases.CASES[name]
    if name not in _DRIVERS:
        _DRIVERS[name] = _driver(fn, kinds)
    drive, n_out = _DRIVERS[name]
    out = np.zeros((L, n_out))
    drive(np.ascontiguousarray(F), np.ascontiguousarray(I), out)
    return out


floats = st.floats(-20, 20, allow_nan=False) | st.sampled_from([0.0, -0.0, 1.0, -1.0, 0.5, 1e-300])
ints = st.integers(0, 12)


@pytest.mark.parametrize("name", sorted(lane_cases.CASES))
@settings(max_examples=40)
@given(data=st.data())
def test_lane_form_equals_the_scalar_function_lane_by_lane(name, data):
    fn, kinds = lane_cases.CASES[name]
    vals = [[data.draw(floats if k == "f" else ints) for _ in range(L)] for k in kinds]
    F = np.array([v if k == "f" else [0.0] * L for v, k in zip(vals, kinds)], dtype=float)
    I = np.array([v if k == "i" else [0] * L for v, k in zip(vals, kinds)], dtype=np.int64)
    got = _lanes_of(name, F, I)
    for lane in range(L):
        want = np.array(fn(*[vals[i][lane] for i in range(len(kinds))]), dtype=float)
        np.testing.assert_array_equal(got[lane], want, err_msg=f"lane {lane} of {name}")


# a few values, signed zeros among them, so that lanes often share the bits of their arguments
_pool = st.lists(st.sampled_from([0.0, -0.0, 0.3, -0.7, 1.5, 2.0, 1e-300]) | floats, min_size=1, max_size=3)


@settings(max_examples=60)
@given(data=st.data())
def test_calls_shared_by_lanes_give_each_lane_its_own_result(data):
    """A libm or vector-libm call whose arguments have the same bits in every active lane is made once
    (auvtrack.jit.lane_values, auvtrack.jit.vecmath): each lane still gets the scalar function's result bit for
    bit, with the lanes of a branch all alike, alike but for a signed zero, or mixed."""
    fn, kinds = lane_cases.CASES["shared"]
    xs, ps = data.draw(_pool), data.draw(_pool)
    F = np.array([[data.draw(st.sampled_from(xs)) for _ in range(L)], [data.draw(st.sampled_from(ps)) for _ in range(L)]])
    got = _lanes_of("shared", F, np.zeros((2, L), dtype=np.int64))
    for lane in range(L):
        want = np.array(fn(F[0, lane], F[1, lane]), dtype=float)
        assert got[lane].tobytes() == want.tobytes(), f"lane {lane}: {got[lane]} != {want}"


def test_masked_stores_keep_the_other_lanes():
    """Stores under a mask write only their lanes; the array of the other lanes is untouched."""
    lane = lane_version(lane_cases.stores)

    @numba.njit
    def drive(a, x, out):
        r = lane(as_lanes(a, L), as_lanes(x, L)[0], full_mask(L))
        for k in range(L):
            out[k] = get_lane(r, k)

    rng = np.random.default_rng(3)
    a = rng.normal(size=(6, L))
    x = rng.uniform(-1, 7, size=(1, L))
    want_a = a.copy()
    want = np.array([lane_cases.stores.py_func(want_a[:, k], x[0, k]) for k in range(L)])  # columns in place
    out = np.zeros(L)
    drive(a, x, out)
    np.testing.assert_array_equal(out, want)
    np.testing.assert_array_equal(a, want_a)



@settings(max_examples=40)
@given(data=st.data())
def test_loads_and_stores_at_each_lanes_own_index(data):
    """Indexing an array of lanes with an index of lanes: each lane reads and writes its own element,
    whether the lanes' indexes are all alike (one vector load or store) or not (one per lane), in 1-D
    and in 2-D next to a plain index."""
    if "gathers" not in _DRIVERS:
        lane = lane_version(lane_cases.gathers)

        @numba.njit
        def drive(a, b, i, j, out):
            r = lane(as_lanes(a, L), as_lanes(b, L), as_lanes(i, L)[0], as_lanes(j, L)[0], full_mask(L))
            for k in range(L):
                out[k] = get_lane(r, k)

        _DRIVERS["gathers"] = drive
    drive = _DRIVERS["gathers"]
    rng = np.random.default_rng(data.draw(st.integers(0, 2**32 - 1)))
    a, b = rng.normal(size=(5, L)), rng.normal(size=(5, 3, L))
    alike = data.draw(st.booleans())
    i = np.full((1, L), data.draw(st.integers(0, 4))) if alike else rng.integers(0, 5, size=(1, L))
    j = rng.integers(0, 3, size=(1, L))
    want_a, want_b = a.copy(), b.copy()
    want = np.array([lane_cases.gathers.py_func(want_a[:, k], want_b[:, :, k], i[0, k], j[0, k]) for k in range(L)])
    out = np.zeros(L)
    drive(a, b, i, j, out)
    assert out.tobytes() == want.tobytes()
    assert a.tobytes() == want_a.tobytes() and b.tobytes() == want_b.tobytes()

def test_unsupported_constructs_are_refused_by_name(tmp_path):
    f = tmp_path / "odd_law.py"
    f.write_text("from auvtrack.jit import njit\n\n@njit\ndef odd(x):\n    for v in (1.0, 2.0):\n"
                 "        x = x + v\n    return x\n")
    odd = load_module(str(f)).odd
    with pytest.raises(NotLaneable, match="only 'for name in range"):
        lane_version(odd)


def test_the_lane_form_is_readable_source():
    src = lane_source(lane_cases.helper)
    assert src.startswith("def helper__lanes(x, y, _m):") and "_LN.sel(" in src


# ------------------------------------------------------------------ each controller's law

def _states(prep, n, seed):
    """n states near the run's start and reference times (what the law sees early in a run)."""
    from auvtrack.reference import eval_reference

    rng = np.random.default_rng(seed)
    X = prep.plant.x0 + rng.normal(0.0, 0.02, (n, prep.plant.x0.size))
    T = rng.uniform(0.0, 2.0, n)
    refm = np.zeros((n, 3, 3))
    for i in range(n):
        eval_reference(prep.ref_p, T[i], refm[i])
    return X, T, refm


@pytest.mark.parametrize("kind", builtin_controllers())
def test_each_law_in_lane_form_equals_the_scalar_law(kind):
    """Each law, rewritten to lanes, gives the scalar law's status and outputs bit for bit: at states
    near the run's start, with a finite actuator reach (the saturation-aware forms are exercised)."""
    from auvtrack.control.contract import WORK_SIZE, LawArgs, LawOutputs, Measured
    from auvtrack.vehicle.kinematics import attitude

    preps = [prepare(load_scenario(PAPER, {"controller.kind": kind, "seed": i, "sim.duration": 1.0}))
             for i in range(L)]
    law = kernels.kernel_module(preps[0].key).law
    lane_law, lane_att = lane_version(law), lane_version(attitude)
    X, T, refm = _states(preps[0], L, 11)
    nxc, naux = preps[0].controller.x0.size, max(1, int(preps[0].si[engine.SI.n_aux]))
    cp = np.stack([p.cp for p in preps])
    vp = np.stack([p.vp_nom for p in preps])
    xc = np.stack([p.controller.x0 for p in preps])
    path = np.stack([p.ref_p for p in preps])
    rng = np.random.default_rng(5)
    hi = rng.uniform(5.0, 60.0, (L, 3))  # a finite reach, different per run
    lo = -hi * rng.uniform(0.5, 1.0, (L, 3))
    ap = rng.uniform(-1.0, 1.0, (L, 3)) * hi
    h = np.zeros(L)

    @numba.njit
    def scalar(X, T, refm, path, cp, vp, xc, lo, hi, ap, h, tau, dxc, aux, st):
        work = np.zeros(WORK_SIZE)
        for i in range(X.shape[0]):
            x = X[i]
            y = Measured((x[0], x[1], x[2], x[3], x[4]), (x[5], x[6], x[7], x[8], x[9]), attitude(x[3], x[4]))
            args = LawArgs(refm[i], path[i], cp[i], vp[i], (lo[i, 0], lo[i, 1], lo[i, 2]),
                           (hi[i, 0], hi[i, 1], hi[i, 2]), (ap[i, 0], ap[i, 1], ap[i, 2]), h[i], work)
            st[i] = law(T[i], y, xc[i], args, LawOutputs(tau[i], dxc[i], aux[i]))

    @numba.njit
    def lanes(X, T, refm, path, cp, vp, xc, lo, hi, ap, h, tau, dxc, aux, st):
        x = as_lanes(X, L)
        m = full_mask(L)
        lo_, hi_, ap_ = as_lanes(lo, L), as_lanes(hi, L), as_lanes(ap, L)
        y = Measured((x[0], x[1], x[2], x[3], x[4]), (x[5], x[6], x[7], x[8], x[9]), lane_att(x[3], x[4], m))
        args = LawArgs(as_lanes(refm, L), as_lanes(path, L), as_lanes(cp, L), as_lanes(vp, L),
                       (lo_[0], lo_[1], lo_[2]), (hi_[0], hi_[1], hi_[2]), (ap_[0], ap_[1], ap_[2]),
                       as_lanes(h, L)[0], as_lanes(np.zeros((WORK_SIZE, L)), L))
        r = lane_law(as_lanes(T, L)[0], y, as_lanes(xc, L), args,
                     LawOutputs(as_lanes(tau, L), as_lanes(dxc, L), as_lanes(aux, L)), m)
        for k in range(L):
            st[k] = get_lane(r, k)

    out_s = [np.zeros((L, 3)), np.zeros((L, max(nxc, 1))), np.zeros((L, naux)), np.zeros(L, np.int64)]
    scalar(X, T, refm, path, cp, vp, xc, lo, hi, ap, h, *out_s)

    def T_(a):
        return np.ascontiguousarray(np.moveaxis(a, 0, -1))

    out_l = [np.zeros((3, L)), np.zeros((max(nxc, 1), L)), np.zeros((naux, L)), np.zeros(L, np.int64)]
    lanes(T_(X), T[None, :].copy(), T_(refm), T_(path), T_(cp), T_(vp), T_(xc) if nxc else np.zeros((1, L)),
          T_(lo), T_(hi), T_(ap), h[None, :].copy(), *out_l)
    np.testing.assert_array_equal(out_l[3], out_s[3])
    for a, b in zip(out_l[:3], out_s[:3]):
        np.testing.assert_array_equal(a.T, b)


# ------------------------------------------------------------------ whole runs

def _metrics(summary) -> np.ndarray:
    return np.array([summary.metrics[k] for k in METRIC_NAMES])


def _same_run(s, r, bitwise: bool):
    assert s.status == r.status
    assert s.failure == r.failure  # time, cause, detail, state at the stop, last finite state
    assert s.steps == r.meta["steps"]
    a, b = _metrics(s), _metrics(r)
    assert np.array_equal(np.isnan(a), np.isnan(b))
    ok = ~np.isnan(a)
    np.testing.assert_allclose(a[ok], b[ok], rtol=1e-9, atol=0.0)
    if bitwise:
        np.testing.assert_array_equal(a, b)


def _failing_batch(kind: str) -> list[dict]:
    """2 L - 1 runs: different seeds, uncertainty and lengths; pitch limits that stop some runs at different times."""
    cases = []
    limits = [0.004, 0.008, 0.015, 0.03, 80.0]
    for i in range(2 * L - 1):
        cases.append({"controller.kind": kind, "seed": i, "uncertainty.D": 0.01 * i,
                      "sim.duration": 0.6 if i % 3 else 0.45, "sim.theta_limit": limits[i % len(limits)]})
    return cases


@pytest.mark.parametrize("kind", builtin_controllers())
def test_simd_batch_equals_single_runs_with_failures_at_different_times(kind):
    preps = [prepare(load_scenario(PAPER, c)) for c in _failing_batch(kind)]
    singles = [run_prepared(p) for p in preps]
    out = run_batch(preps, backend="simd", workers=2)
    for s, r in zip(out, singles):
        _same_run(s, r, bitwise=True)
    if kind != "open_loop":
        times = {r.failure["time"] for r in singles if r.failure}
        assert len(times) >= 2, "the batch should have lanes failing at different times"
        assert {r.status for r in singles} == {"ok", "failed"}



def test_simd_batch_with_metric_windows_ending_at_different_times_equals_single_runs():
    """The path-following metrics of lanes whose metric windows start and end at different steps (a lane
    stops projecting at the end of its window while the others go on), bit for bit those of single runs."""
    cases = [{"controller.kind": "fxtntsmc", "seed": i, "sim.duration": 0.6,
              "metrics.window": [0.02 * i, 0.15 + 0.04 * i]} for i in range(L)]
    preps = [prepare(load_scenario(PAPER, c)) for c in cases]
    singles = [run_prepared(p) for p in preps]
    for s, r in zip(run_batch(preps, backend="simd", workers=2), singles):
        _same_run(s, r, bitwise=True)
        assert math.isfinite(r.metrics["xtrack_rmse"]) and math.isfinite(r.metrics["along_rmse_late"])

def test_simd_batch_on_the_6dof_plants_equals_single_runs():
    """Both 6-DOF preset modules (Prestero, Fossen) in lanes: a tracking law with noise, sampled-data
    control and a current, roll limits that stop lanes at different times, and the open-loop actuator
    controller (fin and propeller commands) of different lengths; one call, input order."""
    from pathlib import Path

    remus = Path(__file__).resolve().parents[2] / "scenarios" / "remus100.toml"
    limits = [9.0, 9.5, 10.0, 11.0, 180.0]  # above the start roll (8.6 deg)
    track = [{"plant.model": "6dof", "plant.preset": "remus100_prestero", "controller.kind": "fxtntsmc",
              "sim.duration": 0.5 if i % 2 else 0.4, "initial.nu": [1.0, 0.0, 0.0, 0.0, 0.0], "seed": i,
              "initial.phi": 0.15, "sim.phi_limit": limits[i % len(limits)], "sim.control_rate": 100,
              "sensor.sigma_eta": [0.01, 0.01, 0.01, 0.003, 0.003],
              "disturbance": [{"kind": "current", "mean": [0.2, 0.1, 0.0], "sigma": [0.02, 0.02, 0.0]}]}
             for i in range(L + 3)]
    actuate = [{"plant.model": "6dof", "plant.preset": "remus100_fossen", "controller.kind": "open_loop_actuators",
                "controller.delta_r": 0.02 * (i % 5), "sim.duration": 0.3 + 0.05 * (i % 3)} for i in range(L)]
    cases = [c for pair in zip(track, actuate) for c in pair] + track[L:]
    preps = [prepare(load_scenario(remus, c)) for c in cases]
    singles = [run_prepared(p) for p in preps]
    for s, r in zip(run_batch(preps, backend="simd", workers=2), singles):
        _same_run(s, r, bitwise=True)
    track_runs = [r for r, c in zip(singles, cases) if c["controller.kind"] == "fxtntsmc"]
    assert {r.status for r in track_runs} == {"ok", "failed"}
    assert len({r.failure["time"] for r in track_runs if r.failure}) >= 2, "lanes should fail at different times"


def test_simd_mixed_batch_in_input_order():
    """Several controllers, envelopes, estimators, sampled-data control and failures in one call."""
    from batch.test_batch import CASES

    order = [5, 1, 7, 0, 3, 2, 6, 4, 1, 0, 0, 0, 0, 0]
    preps = [prepare(load_scenario(PAPER, CASES[i])) for i in order]
    singles = [run_prepared(p) for p in preps]
    for s, r in zip(run_batch(preps, backend="simd", workers=2), singles):
        _same_run(s, r, bitwise=True)


def test_a_law_without_lane_form_runs_on_threads(tmp_path):
    """A law the rewrite does not handle: the group runs on the thread back end, same results."""
    law = tmp_path / "tuple_loop_law.py"
    law.write_text(textwrap.dedent('''
        from auvtrack.jit import njit
        from auvtrack.control.ftsmc import control as ftsmc_control

        @njit
        def control(t, y, xc, args, out):
            s = 0.0
            for g in (1.0, 2.0):  # iterating a tuple: no lane form
                s += g
            return ftsmc_control(t, y, xc, args, out) + int(s - 3.0)
    '''))
    from auvtrack.batch.runner import MIN_LANES

    base = [prepare(load_scenario(PAPER, {"controller.kind": "ftsmc", "seed": i, "sim.duration": 0.2}))
            for i in range(max(MIN_LANES, 2))]  # enough runs for a block
    preps = [dataclasses.replace(p, key=kernels.KernelKey(str(law), p.key.plant, "plug-in on 5dof")) for p in base]
    with pytest.warns(UserWarning, match="no lane form"):
        out = run_batch(preps, backend="simd", workers=2)
    for s, p in zip(out, base):
        _same_run(s, run_prepared(p), bitwise=True)


def test_a_lane_form_numba_cannot_type_runs_on_threads(tmp_path):
    """A law the rewrite handles but whose lane form does not type (a libm function with no lane
    implementation): found when the group is set up, warned about, run on threads; same results."""
    law = tmp_path / "gamma_law.py"
    law.write_text(textwrap.dedent('''
        import math
        from auvtrack.jit import njit
        from auvtrack.control.ftsmc import control as ftsmc_control

        @njit
        def control(t, y, xc, args, out):
            g = math.gamma(2.0 + min(abs(y.eta[0]), 1.0))  # finite: g - g = 0
            return ftsmc_control(t, y, xc, args, out) + int(g - g)
    '''))
    base = [prepare(load_scenario(PAPER, {"controller.kind": "ftsmc", "seed": i, "sim.duration": 0.2}))
            for i in range(L)]
    preps = [dataclasses.replace(p, key=kernels.KernelKey(str(law), p.key.plant, "gamma plug-in on 5dof"))
             for p in base]
    kernels.lanes_module(preps[0].key)  # the rewrite itself succeeds
    with pytest.warns(UserWarning, match="gamma plug-in on 5dof has no lane form"):
        out = run_batch(preps, backend="simd", workers=2)
    for s, p in zip(out, base):
        _same_run(s, run_prepared(p), bitwise=True)


def test_a_stop_request_reaches_every_lane():
    preps = [prepare(load_scenario(PAPER, {"controller.kind": "ftsmc", "seed": i, "sim.duration": 0.3}))
             for i in range(L + 1)]
    stop = StopSignal()
    stop.set()
    out = _run_simd(preps, stop, 2)
    assert [s.status for s in out] == ["interrupted"] * len(preps)
    assert all(s.steps == 0 and s.t_stop == 0.0 for s in out)


def test_lane_kernel_lives_next_to_its_kernel_in_the_keyed_cache():
    """The SIMD module of a pair is generated in the kernel cache folder (named by the source hash)."""
    from auvtrack import jit as _jit

    key = prepare(load_scenario(PAPER, {"controller.kind": "ftsmc", "sim.duration": 0.01})).key
    module = kernels.lanes_module(key)
    assert module.__file__.startswith(str(_jit.cache_dir() / "kernels"))
    assert module.__file__.endswith(f"{key.name}__lanes.py")
    assert "run__lanes = lane_version(" in kernels.lanes_source(key)
    assert math.isfinite(len(kernels.lanes_source(key)))


def test_warmup_compiles_the_lane_kernel_a_simd_batch_then_uses():
    """``compile_lanes`` compiles run_lanes for exactly the types the SIMD back end passes: a batch
    afterwards compiles nothing; it is marked on disk (``is_compiled(key, lanes=True)``)."""
    preps = [prepare(load_scenario(PAPER, {"controller.kind": "pid", "seed": i, "sim.duration": 0.05}))
             for i in range(L)]
    key = preps[0].key
    assert kernels.compile_lanes(key) and kernels.is_compiled(key, lanes=True)
    run_lanes = kernels.lanes_module(key).run_lanes
    before = list(run_lanes.signatures)
    assert len(before) == 1
    out = run_batch(preps, backend="simd", workers=1)
    assert list(run_lanes.signatures) == before
    for s, p in zip(out, preps):
        _same_run(s, run_prepared(p), bitwise=True)
    assert kernels.warmup([key], lanes=True) == []  # nothing left to compile


def test_a_few_runs_left_over_use_the_single_run_kernel():
    """L + 1 runs: one block of L in lanes, the one left over on the single-run kernel; same results."""
    preps = [prepare(load_scenario(PAPER, {"controller.kind": "ftsmc", "seed": i, "sim.duration": 0.1}))
             for i in range(L + 1)]
    for s, p in zip(run_batch(preps, backend="simd", workers=2), preps):
        _same_run(s, run_prepared(p), bitwise=True)
