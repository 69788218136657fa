"""``simulate``: the one entry point from a scenario to a :class:`Result`.

``simulate`` = :func:`auvtrack.load_scenario` (validation) -> :func:`prepare` (the plant's and the
controller's set-up: everything becomes packed float64 arrays, bundled as the engine takes them)
-> :func:`run_prepared` (one call of the compiled kernel of the (controller, plant) pair) ->
:class:`Result`.
"""
from __future__ import annotations

import math
import threading
import time
import warnings
from dataclasses import dataclass
from typing import Any, Mapping, Sequence

import numpy as np

from .. import __version__
from ..control import spec_for as controller_spec_for
from ..control.contract import CONTROLLER_STATUS
from ..control.registry import PlantView, SetupContext
from ..environment import build_disturbance, pack_disturbances
from ..environment.sensors import noise_table
from ..plant import PlantContext
from ..plant import spec_for as plant_spec_for
from ..vehicle.kinematics import attitude, virtual_point
from ..vehicle.params import VP
from ..vehicle.presets import vehicle_arrays  # noqa: F401  (re-exported: studies use it from here)
from ..reference import build_reference
from ..reference.start import start_note
from ..scenario import Scenario, load_scenario
from ..scenario.designed import design_record
from ..scenario.plan import check_state_memory, plan_run
from ..interrupt import Outcome, run_in_thread
from ..user_modules import first_line, load_module
from ..engine import loop as engine
from ..engine import kernels
from ..channels import BASE_CHANNELS, LOG_ROW, channel_names
from ..engine.loop import ControllerBundle, EnvironmentBundle, Outputs, PlantBundle, Settings
from ..plant.contract import SF
from ..metrics import METRICS_SIZE, metrics_finalize, metrics_init
from .compiling import lane_note
from .result import Result

STATE_NAMES = BASE_CHANNELS[LOG_ROW.eta:LOG_ROW.tau]  # eta and nu


class SimulationInterrupted(KeyboardInterrupt):
    """Ctrl-C (or a stop request) ended a simulation; ``result`` holds what was computed.

    Attributes
    ----------
    result : Result
        The partial result, status ``"interrupted"``.
    """

    def __init__(self, result: "Result") -> None:
        super().__init__("simulation interrupted")
        self.result = result


@dataclass(frozen=True)
class Prepared:
    """A scenario turned into the bundles of the engine's kernel (:mod:`auvtrack.engine.loop`).

    Attributes
    ----------
    scenario : Scenario
        The validated scenario.
    key : KernelKey
        The (controller law, plant) pair whose kernel runs it.
    plant, controller, environment, settings
        The engine's bundles.
    ref_p : numpy.ndarray
        Packed reference.
    n_rows : int
        Logged rows.
    channels : tuple of str
        Logged channel names, in column order.
    notes : tuple of str
        Set-up messages for the user.
    resolved : dict
        Derived values recorded in ``run.json``.
    statuses : dict of int to str
        Messages of the controller's status codes.
    tracks : bool
        Whether the controller tracks a reference (else its result carries the manoeuvre it flew,
        :mod:`auvtrack.simulation.manoeuvre`).
    """

    scenario: Scenario
    key: kernels.KernelKey
    plant: PlantBundle
    controller: ControllerBundle
    environment: EnvironmentBundle
    ref_p: np.ndarray
    settings: Settings
    n_rows: int
    channels: tuple[str, ...]
    notes: tuple[str, ...]
    resolved: dict
    statuses: dict
    tracks: bool = True

    # short names for the most used arrays
    si = property(lambda self: self.settings.si, doc="Integer settings (layout :data:`auvtrack.engine.loop.SI`).")
    sf = property(lambda self: self.settings.sf, doc="Float settings (layout :data:`auvtrack.plant.contract.SF`).")
    cp = property(lambda self: self.controller.cp, doc="Packed controller parameters.")
    vp_nom = property(lambda self: self.controller.vp, doc="Packed nominal 5-DOF vehicle.")
    pp = property(lambda self: self.plant.pp, doc="Packed true-plant parameters.")
    noise = property(lambda self: self.environment.noise, doc="Sensor noise table.")

    @property
    def n_steps(self) -> int:
        """RK4 steps planned."""
        return int(self.settings.si[engine.SI.n_steps])

    @property
    def n_state(self) -> int:
        """Plant plus controller states."""
        return self.plant.x0.size + self.controller.x0.size


def _c(a) -> np.ndarray:
    return np.ascontiguousarray(a, dtype=np.float64)


def _plant_key(sc: Scenario, pctx: PlantContext, name: str) -> str:
    """Everything a plant's ``setup`` reads, as text: equal keys, equal set-ups (floats by their exact repr)."""
    import json

    def plain(o: Any) -> Any:
        if isinstance(o, np.ndarray):
            return [str(o.dtype), list(o.shape), o.tobytes().hex()]
        if hasattr(o, "model_dump"):
            return o.model_dump(mode="json")
        raise TypeError(type(o).__name__)

    doc = [name, sc.plant, pctx.eta0, pctx.nu0, pctx.phi0, pctx.p0, pctx.vp_true, pctx.vehicle_record,
           pctx.design_preset, pctx.actuator, pctx.commands, pctx.seed]
    return json.dumps(doc, default=plain, sort_keys=True)


def _plant_setup(plant_spec, sc: Scenario, pctx: PlantContext, cache: dict | None):
    """``plant_spec.setup`` of the run, from ``cache`` when a built-in plant was set up on the same inputs."""
    from dataclasses import replace

    if cache is None or not plant_spec.module.startswith("auvtrack."):
        return plant_spec.setup(sc.plant, pctx)  # a plug-in plant's set-up is the user's: never reused
    try:
        key = _plant_key(sc, pctx, plant_spec.name)
    except TypeError:  # an input without a text form: set up again
        return plant_spec.setup(sc.plant, pctx)
    cpl = cache.get(key)
    if cpl is None:
        cpl = cache[key] = plant_spec.setup(sc.plant, pctx)
    return replace(cpl, pp=np.array(cpl.pp, dtype=np.float64), x0=np.array(cpl.x0, dtype=np.float64))


def prepare(scenario: Scenario, *, plant_cache: dict | None = None) -> Prepared:
    """Build every array the compiled engine needs from a validated scenario.

    Parameters
    ----------
    scenario : Scenario
        A validated scenario (:func:`auvtrack.load_scenario`).
    plant_cache : dict, optional
        Set-ups of built-in plants already made, by their inputs (the plant section, the initial
        state, the vehicles, the actuator, what the controller commands, the seed): runs that
        differ in their controller's gains only (a tuning's candidates) set their plant up once.
        The run gets its own copies of the cached arrays; the dict is filled as runs are prepared.

    Returns
    -------
    Prepared
        Packed float64 arrays in the engine's bundles, the logged channel names and the set-up
        notes.

    Raises
    ------
    ValueError
        If the plant or the controller refuses the set-up (e.g. a start on the envelope with the
        treatment off), naming the field, or the run plan exceeds the scenario's ``[limits]``
        (:class:`~auvtrack.scenario.ScenarioError`, :func:`auvtrack.scenario.plan.plan_run`).
    """
    sc = scenario
    cspec = controller_spec_for(sc.controller)
    plant_spec = plant_spec_for(sc.plant)
    vp_nom, vp_true, record = vehicle_arrays(sc)
    eta0, nu0 = tuple(float(v) for v in sc.initial.eta), tuple(float(v) for v in sc.initial.nu)
    pctx = PlantContext(eta0=eta0, nu0=nu0, phi0=float(sc.initial.phi), p0=float(sc.initial.p), vp_true=vp_true,
                        vehicle_record=record, design_preset=sc.vehicle.preset, actuator=sc.actuator,
                        commands=cspec.command_on(plant_spec), seed=sc.seed)
    cpl = _plant_setup(plant_spec, sc, pctx, plant_cache)
    plant_module = cpl.module or plant_spec.module
    ref = build_reference(dict(sc.reference))
    ref_p = ref.pack()
    p0, v0, a0 = ref.evaluate(0.0)
    refm0 = np.vstack([p0, v0, a0])
    p1 = np.array(virtual_point(eta0, attitude(eta0[3], eta0[4]), vp_nom[VP.ell]))
    view = PlantView(plant_module, plant_spec.state, plant_spec.command, _c(cpl.x0), _c(cpl.pp))
    ctx = SetupContext(vp_nom=vp_nom, refm0=refm0, e0=p1 - p0, seed=sc.seed, eta0=eta0, nu0=nu0,
                       actuator=sc.actuator, plant=view, commands=pctx.commands,
                       sections={k: getattr(sc, k) for k in cspec.sections},
                       dt=sc.sim.dt, control_rate=sc.sim.control_rate)
    cc = cspec.setup(sc.controller, ctx)
    channels = channel_names(cc.aux_names, cpl.log_names)
    plan = plan_run(sc, len(channels))  # every size checked against [limits] before any allocation
    check_state_memory(sc, plan, {"plant": np.size(cpl.x0) + np.size(cpl.pp),
                                  "controller": np.size(cc.xc0) + np.size(cc.cp)})
    tables = pack_disturbances([build_disturbance(dict(d)) for d in sc.disturbance], sc.sim.duration, sc.seed)
    dt = sc.sim.dt
    n_steps, log_every, ctrl_every = plan.n_steps, plan.log_every, plan.control_every
    naux = len(cc.aux_names)
    si = engine.SI.pack(np.int64, n_steps=n_steps, log_every=log_every, ctrl_every=ctrl_every, n_aux=naux,
                        path_metrics=int(sc.metrics.path))
    t0, t1 = sc.metrics.window
    phi_limit = getattr(sc.sim, "phi_limit", 90.0)
    sf = SF.pack(dt=dt, theta_lim=math.radians(sc.sim.theta_limit), state_lim=sc.sim.state_limit, win_t0=t0,
                 win_t1=t1 if math.isfinite(t1) else 1e300, phi_lim=math.radians(phi_limit))
    sigma = (*sc.sensor.sigma_eta, *sc.sensor.sigma_nu)
    if ctrl_every == 0 and any(sigma):  # the schema refuses this too: never drop noise silently
        raise ValueError("sensor: noise needs sim.control_rate > 0")
    noise = noise_table(sc.seed, plan.control_samples if ctrl_every else 1, sigma)
    key = kernels.KernelKey(cc.law or cspec.module, plant_module, f"{cspec.name} on {plant_spec.name}")
    plugins = [m for m in (key.law, key.plant) if not m.startswith("auvtrack.")]
    lanes = lane_note(key) if plugins else None  # a plug-in outside the lane subset: said now, not mid-batch
    return Prepared(
        scenario=sc, key=key,
        plant=PlantBundle(_c(cpl.pp), _c(cpl.x0)),
        controller=ControllerBundle(_c(cc.cp), _c(cc.xc0), _c(vp_nom)),
        environment=EnvironmentBundle(_c(tables.rows), _c(tables.current), _c(noise)),
        ref_p=_c(ref_p), settings=Settings(si, sf),
        n_rows=plan.log_rows,
        channels=channels,
        notes=tuple(cpl.notes) + tuple(cc.notes) + tuple(n for n in [start_note(ref, p1, vp_nom[VP.ell])]
                                                            if n and cspec.tracks)  # open loop: no tracking
        + ((f"{', '.join(plugins)}: {lanes}",) if lanes else ()),
        resolved={"vehicle": cpl.resolved.get("vehicle", {}), "plant": cpl.resolved,
                  "controller": {**cc.resolved, **design_record(sc)}},
        statuses={**CONTROLLER_STATUS, **cspec.statuses, **cc.statuses},
        tracks=cspec.tracks,
    )


def outputs_for(prep: Prepared, rows: int | None = None) -> Outputs:
    """Fresh output arrays for one run of ``prep`` (``rows`` logged rows; default all, 0 = metrics only).

    Parameters
    ----------
    prep : Prepared
        The run.
    rows : int, optional
        Rows of the log.

    Returns
    -------
    Outputs
        Log (NaN), initialised metrics accumulator, failure state and info arrays.
    """
    n = prep.n_rows if rows is None else rows
    acc = np.zeros(METRICS_SIZE)
    metrics_init(acc)
    return Outputs(np.full((n, len(prep.channels)), np.nan), acc, np.zeros((2, prep.n_state)),
                   np.zeros(engine.INFO_SIZE, dtype=np.int64))


def call_kernel(prep: Prepared, out: Outputs) -> tuple[int, int, float]:
    """Run the kernel of ``prep`` into ``out``; return (cause, rows logged, stop time)."""
    run = kernels.kernel(prep.key)
    cause, rows, t_stop = run(prep.plant, prep.controller, prep.environment, prep.ref_p, prep.settings, out)
    return int(cause), int(rows), float(t_stop)


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

    Raises
    ------
    SimulationInterrupted
        On Ctrl-C during the run (within about a second); its ``result`` is the partial run.
    """
    from .compiling import ensure_compiled

    ensure_compiled([prep])
    out = outputs_for(prep)
    wall = time.perf_counter()

    def stop() -> None:
        out.info[engine.INFO_STOP] = 1

    if threading.current_thread() is threading.main_thread():
        outcome = run_in_thread(lambda: call_kernel(prep, out), stop, reraise=False)
    else:
        try:
            outcome = Outcome(call_kernel(prep, out), False, False)
        except Exception as exc:  # a law or plant that raised inside the compiled loop
            outcome = Outcome(exc, False, False)
    wall = time.perf_counter() - wall
    if outcome.abandoned:  # the law or plant never returned to the loop: keep what it logged
        result = _partial(prep, out, wall, "interrupted",
                          "interrupted by the user; the run did not stop at the request (the law or plant was still "
                          "computing) and was abandoned")
        result.meta["abandoned"] = True
        raise SimulationInterrupted(result)
    if isinstance(outcome.value, BaseException):
        exc = outcome.value
        if not isinstance(exc, Exception):
            raise exc
        return _partial(prep, out, wall, "exception", first_line(exc))
    cause, rows, t_stop = outcome.value
    result = result_from(prep, out, cause, rows, t_stop, wall)
    if outcome.interrupted or cause == engine.CAUSE_INTERRUPTED:
        raise SimulationInterrupted(result)
    return result


def _partial(prep: Prepared, out: Outputs, wall: float, cause: str, detail: str) -> Result:
    """The result of a run that left the compiled loop without a stop cause: what it logged, a failure record.

    The rows logged are those whose time is written; the state named is the last logged one.
    """
    rows = int(np.count_nonzero(np.isfinite(out.log[:, 0]))) if out.log.shape[0] else 0
    steps = int(out.info[engine.INFO_STEPS])
    t = steps * float(prep.settings.sf[SF.dt])
    sc = prep.scenario
    channels = {name: out.log[:rows, j].copy() for j, name in enumerate(prep.channels)}
    state = {n: float(channels[n][-1]) for n in STATE_NAMES} if rows else {}
    failure = {"time": t, "cause": cause, "detail": detail, "state": state}
    resolved = sc.to_dict()
    resolved["resolved"] = prep.resolved
    t0, t1 = sc.metrics.window
    metrics = metrics_finalize(out.acc, t0, min(t1, t))
    meta = {"version": __version__, "wall_time_s": wall, "notes": list(prep.notes), "steps": steps,
            "steps_planned": prep.n_steps}
    return _with_manoeuvre(prep, Result(channels, resolved, "interrupted" if cause == "interrupted" else "failed",
                                        failure, metrics, meta))


def result_from(prep: Prepared, out: Outputs, cause: int, rows: int, t_stop: float, wall: float) -> Result:
    """Wrap a finished kernel call in a :class:`Result` (trajectory, metrics, status, failure, meta)."""
    failure = None if cause == engine.CAUSE_NONE else failure_record(cause, t_stop, out.fail_state, prep,
                                                                     int(out.info[engine.INFO_STATUS]))
    sc = prep.scenario
    t0, t1 = sc.metrics.window
    metrics = metrics_finalize(out.acc, t0, min(t1, t_stop))
    channels = {name: out.log[:rows, j].copy() for j, name in enumerate(prep.channels)}
    resolved = sc.to_dict()
    resolved["resolved"] = prep.resolved
    meta = {"version": __version__, "wall_time_s": wall, "notes": list(prep.notes),
            "steps": int(out.info[engine.INFO_STEPS]), "steps_planned": prep.n_steps}
    return _with_manoeuvre(prep, Result(channels, resolved, status_of(cause), failure, metrics, meta))


def _with_manoeuvre(prep: Prepared, result: Result) -> Result:
    """``result``, with ``meta["manoeuvre"]`` (the figures, or None when none was flown) for a controller that does not track."""
    if not prep.tracks:
        from .manoeuvre import manoeuvre_metrics

        result.meta["manoeuvre"] = manoeuvre_metrics(result, prep.scenario.controller)
    return result


def status_of(cause: int) -> str:
    """``"ok"``, ``"interrupted"`` or ``"failed"`` for a kernel's stop cause."""
    if cause == engine.CAUSE_NONE:
        return "ok"
    return "interrupted" if cause == engine.CAUSE_INTERRUPTED else "failed"


def failure_record(cause: int, t: float, fail_state: np.ndarray, prep: Prepared, status: int = 0) -> dict[str, Any]:
    """The ``Result.failure`` record of a stop: time, cause, detail, state and last finite state.

    Parameters
    ----------
    cause : int
        Kernel stop cause (``engine.CAUSE_*``).
    t : float
        Stop time (s).
    fail_state : numpy.ndarray
        (2, n): the state at the stop and the last finite state.
    prep : Prepared
        The run (for state names and status messages).
    status : int, optional
        The controller's status for ``CAUSE_CONTROLLER``.

    Returns
    -------
    dict
        ``time``, ``cause``, ``detail`` (for a divergence: the component that blew up first),
        ``state`` and, when they differ, ``last_finite_state``.
    """
    if cause == engine.CAUSE_CONTROLLER:
        name = "controller"
        detail = prep.statuses.get(status) or (
            f"status {status}" if status > 0 else f"the controller returned status {status} (statuses are codes > 0)")
    else:
        name, detail = engine.CAUSES.get(cause, ("engine", f"unknown stop cause {cause}"))
        if cause in (engine.CAUSE_NONFINITE, engine.CAUSE_STATE_LIMIT):
            detail += f"; first: {_blown_component(fail_state[0], prep)}"
    record = {"time": float(t), "cause": name, "detail": detail, "state": _state_dict(fail_state[0], prep)}
    if not np.array_equal(fail_state[0], fail_state[1], equal_nan=True):
        record["last_finite_state"] = _state_dict(fail_state[1], prep)
    return record


def _state_names(prep: Prepared) -> list[str]:
    """A name for each component of the stacked [plant state, controller state]."""
    from ..control import spec_for
    from ..plant import spec_for as plant_spec

    plant = list(plant_spec(prep.scenario.plant).state) or [f"plant state {i}" for i in range(prep.plant.x0.size)]
    layout = getattr(load_module(spec_for(prep.scenario.controller).module), "STATE", None)
    names = []
    for i in range(prep.controller.x0.size):
        field = None
        if layout is not None and hasattr(layout, "sizes"):
            for f, size in layout.sizes.items():
                start = getattr(layout, f)
                if start <= i and (size is None or i < start + size):
                    field = f"{f}[{i - start}]"
        names.append(f"controller state {field or i}")
    return plant + names


def _blown_component(state: np.ndarray, prep: Prepared) -> str:
    """The component that is non-finite, else the one beyond sim.state_limit, named, with its value."""
    names = _state_names(prep)
    bad = [i for i, v in enumerate(state) if not np.isfinite(v)]
    if not bad:
        bad = [i for i, v in enumerate(state) if abs(v) > prep.scenario.sim.state_limit]
    if not bad:
        return "none"
    i = bad[0]
    more = f" (and {len(bad) - 1} more)" if len(bad) > 1 else ""
    return f"{names[i] if i < len(names) else i} = {state[i]:.6g}{more}"


def _state_dict(state: np.ndarray, prep: Prepared) -> dict[str, Any]:
    nxp = prep.plant.x0.size
    # the 5-DOF names label the plant's pose (a 6-DOF state has roll at index 3)
    pose = load_module(prep.key.plant).pose
    eta, nu = pose(np.ascontiguousarray(state[:nxp], dtype=np.float64))
    st: dict[str, Any] = {n: float(v) for n, v in zip(STATE_NAMES, (*eta, *nu))}
    if nxp > len(STATE_NAMES):
        st["plant_state"] = [float(x) for x in state[:nxp]]
    if state.size > nxp:
        st["controller_state"] = [float(x) for x in state[nxp:]]
    return st


def simulate(scenario: str | Mapping | Scenario, overrides: Sequence[str] | str | Mapping | None = (), *,
             warn: bool = False) -> Result:
    """Simulate a scenario and return its :class:`Result`.

    Parameters
    ----------
    scenario : str, path, dict or Scenario
        A packaged scenario's name (``"paper"``, ``"lawnmower"``; no ``/``, ``\\`` or ``.``), a
        TOML file path, a scenario dict, or a loaded :class:`~auvtrack.scenario.Scenario`
        (:func:`auvtrack.load_scenario`).
    overrides : list of str, str, dict or None, optional
        ``"dotted.key=value"`` overrides applied on top: a list or tuple of them, one such
        string, or a dict ``{dotted.key: value}`` of TOML values (NumPy scalars and arrays are
        converted, ``None`` is refused); None means none (see :func:`auvtrack.load_scenario`).
    warn : bool, optional
        Also emit the set-up notes (e.g. the paper's initial envelope widening) as ``UserWarning``;
        by default a run does not warn: its notes are in :attr:`Result.notes` (and ``run.json``).

    Returns
    -------
    Result
        Logged channels, metrics, status and failure diagnostic; a failed run keeps its
        partial trajectory.

    Raises
    ------
    ScenarioError
        Bad input, a one-line message naming the source and the field (a ``ValueError``).
    ValueError
        The run plan or the controller's set-up refuses the scenario (:func:`prepare`), or a
        plug-in law raises in its bounds-checked probe run (:func:`auvtrack.simulation.probe.probe`).
    SimulationInterrupted
        On Ctrl-C; its ``result`` holds the partial run.

    Examples
    --------
    >>> import auvtrack
    >>> res = auvtrack.simulate("paper", ["sim.duration=1"])  # doctest: +SKIP
    >>> res.to_pandas().head()  # doctest: +SKIP
    """
    from .probe import probe

    sc = load_scenario(scenario, overrides)
    prep = prepare(sc)
    probe(prep)
    if warn:
        for note in prep.notes:
            warnings.warn(note, stacklevel=2)
    return run_prepared(prep)
