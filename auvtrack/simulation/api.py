"""``simulate``: the one entry point from a scenario to a :class:`Result`."""
from __future__ import annotations

import math
import time
import warnings
from dataclasses import dataclass
from typing import Any, Mapping, Sequence

import numpy as np

from .. import __version__
from ..control import get as get_controller
from ..control.dispatch import CONTROLLER_STATUS
from ..environment import build_disturbance, pack_disturbances
from ..environment.sensors import noise_table
from ..plant.actuators import pack_actuator
from ..plant.kinematics import attitude, virtual_point
from ..plant.presets import get_preset, pack_vehicle
from ..reference import build_reference
from ..scenario import Scenario, load_scenario
from ..scenario.plan import plan_run
from . import engine
from .metrics import METRICS_SIZE, metrics_finalize, metrics_init
from .result import Result

BASE_CHANNELS = ("t", "x", "y", "z", "theta", "psi", "u", "v", "w", "q", "r",
                 "tau_u", "tau_q", "tau_r", "xd", "yd", "zd", "ex", "ey", "ez")
CHI_CHANNELS = ("chi_x", "chi_y", "chi_z")
STATE_NAMES = BASE_CHANNELS[1:11]


@dataclass(frozen=True)
class SetupContext:
    """What a controller's ``setup`` may use besides the scenario.

    Attributes
    ----------
    vp_nom : numpy.ndarray
        Packed nominal vehicle (:mod:`auvtrack.plant.params`).
    refm0 : numpy.ndarray
        Reference at t = 0, rows eta_d, eta_d_dot, eta_d_ddot.
    e0 : numpy.ndarray
        Initial virtual-point error eta1(0) - eta_d(0) (m).
    seed : int
        Scenario seed.
    """

    vp_nom: np.ndarray
    refm0: np.ndarray
    e0: np.ndarray
    seed: int


@dataclass(frozen=True)
class Prepared:
    """A scenario turned into the arrays of :func:`auvtrack.simulation.engine.run_kernel`."""

    scenario: Scenario
    X0: np.ndarray
    si: np.ndarray
    sf: np.ndarray
    cp: np.ndarray
    vp_nom: np.ndarray
    vp_true: np.ndarray
    ref_p: np.ndarray
    d_rows: np.ndarray
    d_cur: np.ndarray
    noise: np.ndarray
    n_rows: int
    channels: tuple[str, ...]
    notes: tuple[str, ...]
    resolved: dict


def vehicle_arrays(sc: Scenario) -> tuple[np.ndarray, np.ndarray, dict]:
    """Nominal and true packed vehicles (uncertainty applied to the true plant) and their record."""
    pre = get_preset(sc.vehicle.preset)
    v = sc.vehicle
    m = np.array(v.m if v.m is not None else pre.m, dtype=float)
    d = np.array(v.d if v.d is not None else pre.d, dtype=float)
    wgml = float(v.wgml if v.wgml is not None else pre.wgml)
    ell = float(v.l if v.l is not None else pre.l)
    u = sc.uncertainty
    vp_nom = pack_vehicle(m, d, wgml, ell, 1.0)
    vp_true = pack_vehicle(m * (1 + u.M), d * (1 + u.D), wgml * (1 + u.G), ell, 1.0 + u.C)
    record = {"preset": pre.name, "m": m.tolist(), "d": d.tolist(), "wgml": wgml, "l": ell,
              "sources": pre.sources,
              "true_plant": {"m": (m * (1 + u.M)).tolist(), "d": (d * (1 + u.D)).tolist(),
                             "wgml": wgml * (1 + u.G), "c_scale": 1.0 + u.C}}
    return vp_nom, vp_true, record


def prepare(scenario: Scenario) -> Prepared:
    """Build every array the compiled engine needs from a validated scenario.

    Parameters
    ----------
    scenario : Scenario
        A validated scenario (:func:`auvtrack.load_scenario`).

    Returns
    -------
    Prepared
        Packed float64 arrays, the logged channel names and the start-treatment notes.

    Raises
    ------
    ValueError
        If the controller refuses the set-up (e.g. a start on the envelope with the
        treatment off), naming the field, or the run plan exceeds the scenario's ``[limits]``
        (:class:`~auvtrack.scenario.ScenarioError`, :func:`auvtrack.scenario.plan.plan_run`).
    """
    sc = scenario
    vp_nom, vp_true, vehicle_record = vehicle_arrays(sc)
    ref = build_reference(dict(sc.reference))
    ref_p = ref.pack()
    eta0 = np.array(sc.initial.eta, dtype=float)
    nu0 = np.array(sc.initial.nu, dtype=float)
    p0, v0, a0 = ref.evaluate(0.0)
    refm0 = np.vstack([p0, v0, a0])
    p1 = np.array(virtual_point(tuple(eta0), attitude(eta0[3], eta0[4]), vp_nom[engine.ELL]))
    ctx = SetupContext(vp_nom=vp_nom, refm0=refm0, e0=p1 - p0, seed=sc.seed)
    cc = get_controller(sc.controller.kind).setup(sc, ctx)
    channels = BASE_CHANNELS + tuple(cc.aux_names) + CHI_CHANNELS
    plan = plan_run(sc, len(channels))  # every size checked against [limits] before any allocation
    tables = pack_disturbances([build_disturbance(dict(d)) for d in sc.disturbance], sc.sim.duration, sc.seed)
    dt = sc.sim.dt
    n_steps, log_every, ctrl_every = plan.n_steps, plan.log_every, plan.control_every
    naux = len(cc.aux_names)
    si = np.array([n_steps, log_every, ctrl_every, cc.code, naux, cc.xc0.size], dtype=np.int64)
    t0, t1 = sc.metrics.window
    sf = np.concatenate([[dt, math.radians(sc.sim.theta_limit), sc.sim.state_limit, t0,
                          t1 if math.isfinite(t1) else 1e300],
                         pack_actuator(sc.actuator.tau_max, sc.actuator.rate_max)])
    sigma = (*sc.sensor.sigma_eta, *sc.sensor.sigma_nu)
    if ctrl_every == 0 and any(sigma):  # the schema refuses this too: never drop noise silently
        raise ValueError("sensor: noise needs sim.control_rate > 0")
    noise = noise_table(sc.seed, plan.control_samples if ctrl_every else 1, sigma)
    X0 = np.concatenate([eta0, nu0, cc.xc0]).astype(np.float64)
    return Prepared(sc, X0, si, sf, np.ascontiguousarray(cc.cp, dtype=np.float64), vp_nom, vp_true,
                    ref_p, tables.rows, tables.current, noise, plan.log_rows, channels, tuple(cc.notes),
                    {"vehicle": vehicle_record, "controller": cc.resolved})


def run_prepared(prep: Prepared) -> Result:
    """Run the compiled engine on prepared arrays and wrap the outcome in a :class:`Result`.

    Parameters
    ----------
    prep : Prepared
        The output of :func:`prepare`; it is not modified, so it can be run again.

    Returns
    -------
    Result
        The logged trajectory, metrics, status and (for a failed run) the failure record.
    """
    log = np.full((prep.n_rows, len(prep.channels)), np.nan)
    acc = np.zeros(METRICS_SIZE)
    metrics_init(acc)
    fail_state = np.zeros(prep.X0.size)
    wall = time.perf_counter()
    cause, rows, t_stop = engine.run_kernel(int(prep.si[engine.SI_CODE]), prep.X0, prep.si, prep.sf, prep.cp, prep.vp_nom, prep.vp_true,
                                            prep.ref_p, prep.d_rows, prep.d_cur, prep.noise, log, acc, fail_state)
    wall = time.perf_counter() - wall
    failure = None if cause == engine.CAUSE_NONE else _failure(cause, t_stop, fail_state, prep)
    sc = prep.scenario
    t0, t1 = sc.metrics.window
    metrics = metrics_finalize(acc, t0, min(t1, t_stop))
    channels = {name: log[:rows, j].copy() for j, name in enumerate(prep.channels)}
    resolved = sc.to_dict()
    resolved["resolved"] = prep.resolved
    meta = {"version": __version__, "wall_time_s": wall, "notes": list(prep.notes),
            "steps": int(prep.si[engine.SI_NSTEPS])}
    return Result(channels, resolved, "ok" if failure is None else "failed", failure, metrics, meta)


def _failure(cause: int, t: float, state: np.ndarray, prep: Prepared) -> dict[str, Any]:
    if cause >= engine.CAUSE_CONTROLLER:
        name = "controller"
        detail = CONTROLLER_STATUS.get(cause - engine.CAUSE_CONTROLLER, f"status {cause - engine.CAUSE_CONTROLLER}")
    else:
        name = {engine.CAUSE_NONFINITE: "nonfinite", engine.CAUSE_PITCH: "pitch_limit",
                engine.CAUSE_STATE_LIMIT: "state_limit"}[cause]
        detail = engine.CAUSES[cause]
    st = {n: float(state[i]) for i, n in enumerate(STATE_NAMES)}
    if state.size > 10:
        st["controller_state"] = [float(x) for x in state[10:]]
    return {"time": float(t), "cause": name, "detail": detail, "state": st}


def simulate(scenario: str | Mapping | Scenario, overrides: Sequence[str] | Mapping = (), *,
             warn: bool = True) -> Result:
    """Simulate a scenario and return its :class:`Result`.

    Parameters
    ----------
    scenario : str, path, dict or Scenario
        A TOML file, a scenario dict, or a loaded :class:`~auvtrack.scenario.Scenario`.
    overrides : sequence of str or dict, optional
        ``"dotted.key=value"`` overrides applied on top (see :func:`auvtrack.load_scenario`).
    warn : bool, optional
        Emit the controller's set-up notes (e.g. an initial envelope widening) as warnings.

    Returns
    -------
    Result
        Logged channels, metrics, status and failure diagnostic; a failed run keeps its
        partial trajectory.

    Examples
    --------
    >>> import auvtrack
    >>> res = auvtrack.simulate("scenarios/paper.toml", ["sim.duration=1"])  # doctest: +SKIP
    >>> res.to_pandas().head()  # doctest: +SKIP
    """
    sc = load_scenario(scenario, overrides)
    prep = prepare(sc)
    if warn:
        for note in prep.notes:
            warnings.warn(note, stacklevel=2)
    return run_prepared(prep)
