"""Compiled closed loop: a plant, the environment, a reference and a controller under fixed-step RK4.

The plant state ``xp`` (the plant module's ``NX`` states) and the controller's internal state
``xc`` (adaptive weights, envelope filters, integrators) are integrated together.  Two modes:

* continuous (``ctrl_every = 0``): the controller and the plant's allocation are evaluated at
  every RK4 stage;
* sampled-data (``ctrl_every = k``): they run every k steps on the measured state, and the
  actuator command and the controller's state derivative are held (zero-order hold) until the
  next sample.  The controller sees the plant's 5-DOF pose plus row k of the seeded noise table.

Logs and metrics always use the true state and the input the plant actually produces; the
path-following metrics use the vehicle's navigation point (its origin) against the path.  One row
is logged every ``log_every`` steps into a preallocated array (O(N) in total).  After every step
the state is checked; a failure stops the run at once and keeps what was logged.  Every 1024
steps the loop reads ``info[INFO_STOP]``: a non-zero value (set from another thread, e.g. on
Ctrl-C) stops the run with cause :data:`CAUSE_INTERRUPTED`.

**How the kernels are made.**  The functions marked ``@kernel_part`` below call the controller's
compiled law as ``law(...)`` and the plant's compiled functions as ``plant.f(...)``.  Here those
names are the contracts' documented stubs (:func:`auvtrack.control.contract.control`,
:mod:`auvtrack.plant.contract`), so this file is plain, checkable Python; it is not compiled
here: :mod:`auvtrack.engine.kernels` writes, for each (controller, plant) pair a run needs, a
module that binds ``law`` and ``plant`` to the real ones and holds a verbatim copy of these
functions, and compiles it once (cached on disk).  This file is the one source of the loop.

Arguments come in bundles (:class:`PlantBundle`, :class:`ControllerBundle`,
:class:`EnvironmentBundle`, :class:`Settings`, :class:`Outputs`; :class:`Stacked` and
:class:`StackedOutputs` for many runs); integer settings ``si`` and float settings ``sf`` follow
the layouts :data:`SI` and :data:`~auvtrack.plant.contract.SF`.

Performance note: arrays are passed whole and indexed, never sliced, in the hot path (a slice
is a reference-counted view whose atomic inc/decrements cost more than the arithmetic).
"""
from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import prange

from ..control.contract import WORK_SIZE, LawArgs, LawOutputs, Measured
from ..control.contract import control as law
from ..control.tracking import lumped_disturbance
from ..environment.dispatch import time_only
from ..environment.sensors import measure
from ..packing import packed_layout
from ..plant import contract as plant
from ..plant.contract import CAUSE_PITCH, CAUSE_ROLL, SCRATCH_SIZE, SF
from ..reference import eval_reference
from ..metrics import effort_update, metrics_update, path_update, saturation_update
from ..vehicle.dynamics import nu_dot
from ..vehicle.kinematics import attitude, virtual_point
from ..vehicle.params import VP
from ..channels import LOG_ROW
from ..jit import njit, njit_noalloc
from ..jit.lane_values import as_lanes, first_lanes, get_lane

SI = packed_layout("IntSettings", n_steps=1, log_every=1, ctrl_every=1, n_aux=1, path_metrics=1)
"""Engine integer settings: RK4 steps, steps per logged row, steps per control sample (0:
continuous), the controller's channel count, whether the path-following metrics are computed (1)
or skipped (0: ``metrics.path = false``)."""
INFO_STOP, INFO_STEPS, INFO_STATUS = 0, 1, 2
INFO_SIZE = 3
STOP_POLL = 1024  # steps between two reads of the stop flag (a power of two)

CAUSE_NONE, CAUSE_NONFINITE, CAUSE_STATE_LIMIT, CAUSE_INTERRUPTED = 0, 1, 3, 4
CAUSE_CONTROLLER = 10  # a controller status: the code itself is in info[INFO_STATUS]
CAUSES = {
    CAUSE_NONFINITE: ("nonfinite", "non-finite state (NaN or Inf)"),
    CAUSE_PITCH: ("pitch_limit", "pitch limit exceeded (|theta| beyond sim.theta_limit)"),
    CAUSE_STATE_LIMIT: ("state_limit", "state limit exceeded (divergence, |state| > sim.state_limit)"),
    CAUSE_INTERRUPTED: ("interrupted", "interrupted by the user (Ctrl-C) or a stop request"),
    CAUSE_ROLL: ("roll_limit", "roll limit exceeded (|phi| beyond sim.phi_limit)"),
}
"""Stop causes other than a controller status: code -> (name, detail)."""
STATUS_NONFINITE_INPUT = 3


class PlantBundle(NamedTuple):
    """The true plant: packed parameters ``pp`` and initial state ``x0`` (plant module layout)."""

    pp: np.ndarray
    x0: np.ndarray


class ControllerBundle(NamedTuple):
    """The controller: packed gains ``cp``, initial internal state ``x0``, nominal vehicle ``vp``."""

    cp: np.ndarray
    x0: np.ndarray
    vp: np.ndarray


class EnvironmentBundle(NamedTuple):
    """Disturbance tables ``rows`` and ``current`` (:mod:`auvtrack.environment`), sensor ``noise``."""

    rows: np.ndarray
    current: np.ndarray
    noise: np.ndarray


class Settings(NamedTuple):
    """Integer settings ``si`` (:data:`SI`) and float settings ``sf`` (:data:`~auvtrack.plant.contract.SF`)."""

    si: np.ndarray
    sf: np.ndarray


class Outputs(NamedTuple):
    """Written by the kernel.

    ``log`` (n_rows, n_channels); ``acc`` the metrics accumulator; ``fail_state`` (2, nxp + nxc):
    row 0 the state at the stop, row 1 the last finite state (the state at the start of the
    failing step); ``info`` int64 (INFO_*): the stop request (read), the steps run and the
    controller's failure status (written).
    """

    log: np.ndarray
    acc: np.ndarray
    fail_state: np.ndarray
    info: np.ndarray


class Loop(NamedTuple):
    """What every stage of one run reads: plant, controller, reference, environment, control mode."""

    pp: np.ndarray
    cp: np.ndarray
    vp: np.ndarray
    path: np.ndarray
    rows: np.ndarray
    current: np.ndarray
    ctrl_every: int
    h: float


class Buffers(NamedTuple):
    """Arrays one run reuses at every stage: reference rows, law scratch, plant scratch, actuator command."""

    refm: np.ndarray
    work: np.ndarray
    scr: np.ndarray
    cmd: np.ndarray


class Rk4(NamedTuple):
    """Arrays of one RK4 step: stage derivatives, stage states and the state after the step.

    ``kp1`` .. ``kp4`` (plant) and ``kc1`` .. ``kc4`` (controller) are the stage derivatives,
    ``xps``, ``xcs`` the stage states, ``xpn``, ``xcn`` the states after the step.
    """

    kp1: np.ndarray
    kp2: np.ndarray
    kp3: np.ndarray
    kp4: np.ndarray
    kc1: np.ndarray
    kc2: np.ndarray
    kc3: np.ndarray
    kc4: np.ndarray
    xps: np.ndarray
    xcs: np.ndarray
    xpn: np.ndarray
    xcn: np.ndarray


class Stacked(NamedTuple):
    """The inputs of many runs with equal array shapes: row ``i`` of each is run ``i``'s array."""

    pp: np.ndarray
    xp0: np.ndarray
    cp: np.ndarray
    xc0: np.ndarray
    vp: np.ndarray
    rows: np.ndarray
    current: np.ndarray
    noise: np.ndarray
    path: np.ndarray
    si: np.ndarray
    sf: np.ndarray


class StackedOutputs(NamedTuple):
    """What many runs write: logs, metrics accumulators, stop states, step counts, causes and stop times."""

    log: np.ndarray
    acc: np.ndarray
    fail_state: np.ndarray
    info: np.ndarray
    cause: np.ndarray
    t_stop: np.ndarray


KERNEL_PARTS: dict[str, str] = {}
"""Name of each kernel part -> the decorator it is compiled with in a generated kernel module."""
LANE_PARTS: dict[str, str] = {}
"""The same for the parts of the SIMD batch module of a pair (:func:`run_lanes`)."""
LANES = 8
"""Runs per block of the lane kernels: the float64 lanes of one 512-bit AVX-512 register (two AVX2 registers)."""


def kernel_part(decorator: str, *, lanes: bool = False):
    """Mark a function as part of the loop that :mod:`auvtrack.engine.kernels` copies per (law, plant).

    Parameters
    ----------
    decorator : str
        Python source of the decorator the copy gets, e.g. ``"njit(nogil=True)"``.
    lanes : bool, optional
        A part of the SIMD batch module (compiled only when that back end runs) instead of the
        kernel module.

    Returns
    -------
    callable
        A decorator that records the function and returns it unchanged (not compiled here).
    """
    def mark(fn):
        (LANE_PARTS if lanes else KERNEL_PARTS)[fn.__name__] = decorator
        return fn
    return mark


def example_arguments() -> tuple:
    """Arguments of ``run`` with the exact types every prepared run passes (to compile ahead of time).

    Every array is C-contiguous and writeable: float64 except the int64 ``si`` and ``info``.
    """
    f1, f2 = np.zeros(1), np.zeros((1, 1))
    return (PlantBundle(f1, f1), ControllerBundle(f1, f1, f1), EnvironmentBundle(f2, f2, f2), f1,
            Settings(np.zeros(SI.size, np.int64), np.zeros(SF.size)),
            Outputs(f2, f1, f2, np.zeros(INFO_SIZE, np.int64)))


def run__lanes(pb, cb, env, ref_p, settings, out, mask):
    """The lane form of :func:`run` (:mod:`auvtrack.engine.lanes`); each SIMD batch module binds its own."""
    raise NotImplementedError("bound per lane kernel")


# ------------------------------------------------------------------ helpers (compiled here)

@njit
def state_free_disturbance(d_rows):
    """True when omega depends on time only (paper and pulse components), not on the state."""
    for k in range(d_rows.shape[0]):
        if not time_only(d_rows[k, 0]):
            return False
    return True


@njit_noalloc
def finite3(v):
    """True when the three entries of ``v`` are finite."""
    return math.isfinite(v[0]) and math.isfinite(v[1]) and math.isfinite(v[2])


@njit_noalloc(inline="always")
def scan_state(x, state_lim):
    """(any non-finite, any |x_i| > state_lim) over one state array, one pass."""
    nonfinite = over = False
    for i in range(x.shape[0]):
        v = x[i]
        if not math.isfinite(v):
            nonfinite = True
        elif abs(v) > state_lim:
            over = True
    return nonfinite, over


@njit
def record_stop(xp, xc, xp_last, xc_last, fail_state):
    """Rows of ``fail_state``: the state [xp, xc] at the stop and the last finite state [xp_last, xc_last]."""
    n = xp.shape[0]
    for i in range(n):
        fail_state[0, i], fail_state[1, i] = xp[i], xp_last[i]
    for i in range(xc.shape[0]):
        fail_state[0, n + i], fail_state[1, n + i] = xc[i], xc_last[i]


# ------------------------------------------------------------------ kernel parts (compiled per law, plant)

@kernel_part("njit_noalloc(inline='always')")
def state_cause(xp, xc, sf):
    """Failure cause after a step (precedence: non-finite, the plant's attitude limits, state limit)."""
    nf_p, over_p = scan_state(xp, sf[SF.state_lim])
    nf_c, over_c = scan_state(xc, sf[SF.state_lim])
    nonfinite, over = nf_p or nf_c, over_p or over_c
    if nonfinite:
        return CAUSE_NONFINITE
    cause = plant.attitude_cause(xp, sf)
    if cause != CAUSE_NONE:
        return cause
    if over:
        return CAUSE_STATE_LIMIT
    return CAUSE_NONE


@kernel_part("njit_noalloc(inline='always')")
def plant_attitude(xp):
    """(cos theta, sin theta, cos psi, sin psi) of the plant state, through its 5-DOF ``pose``."""
    eta = plant.pose(xp)[0]
    return attitude(eta[3], eta[4])


@kernel_part("njit_noalloc(inline='always')")
def law_call(t, eta, nu, att, xc, xp, lp, buf, out):
    """The law at the measured (eta, nu, att), told what the actuators can do at the plant state ``xp``."""
    lo, hi, ap = plant.feedback(xp, buf.cmd, lp.pp)
    return law(t, Measured(eta, nu, att), xc, LawArgs(buf.refm, lp.path, lp.cp, lp.vp, lo, hi, ap, lp.h, buf.work),
               out)


@kernel_part("njit_noalloc")
def stage(t, xp, xc, att, lp, buf, dxp, out, fresh):
    """One right-hand-side evaluation: write dxp (and ``out.dxc``); return (controller status, saturation flags).

    ``att`` is the attitude of ``xp`` (computed once per stage by the caller).  In continuous
    mode the law and the plant's allocation run here (``buf.cmd`` is the previous command when
    the allocation starts and the new one after it); in sampled-data mode ``buf.cmd`` holds the
    sample's command and the caller has filled ``out.dxc`` with the held controller derivative.
    With ``fresh`` false the reference and the plant's cached disturbance of the previous call are
    reused: the loop passes false only for the second of two stages at the same time whose
    disturbance does not depend on the state (RK4 stages 2 and 3), so the values are the same
    numbers.
    """
    if fresh:
        eval_reference(lp.path, t, buf.refm)
    flags = 0
    if lp.ctrl_every == 0:
        eta, nu = plant.pose(xp)
        status = law_call(t, eta, nu, att, xc, xp, lp, buf, out)
        if status != 0:
            return status, flags
        u = out.u
        flags = plant.allocate((u[0], u[1], u[2]), eta, nu, xp, lp.pp, buf.cmd, 0.0, buf.cmd)
    plant.rhs(t, xp, att, buf.cmd, (lp.rows, lp.current), lp.pp, buf.scr, fresh, dxp)
    return 0, flags


@kernel_part("njit_noalloc")
def control_sample(t, eta, nu, att, xc, xp, lp, buf, out):
    """The law at one control sample (sampled-data mode), behind a call.

    A law compiled with ``inline="always"`` is copied into every function that calls it; called
    from here, :func:`run` holds no copy of its own (the law is inlined into :func:`stage`, where
    it runs at every stage, and here), which halves what Numba compiles of it.  Once per sample,
    the call costs nothing measurable.
    """
    return law_call(t, eta, nu, att, xc, xp, lp, buf, out)


@kernel_part("njit_noalloc(inline='always')")
def sample(t, k, xp, xc, lp, buf, noise, out, rk, cmd_sample):
    """One control sample (sampled-data mode): measure, the law, the allocation; hold the command and ``out.dxc``.

    The law sees the plant's pose plus row ``k // ctrl_every`` of ``noise``; the new command is
    written to ``buf.cmd`` and the law's state derivative to ``rk.kc2`` .. ``rk.kc4`` (held for every
    stage until the next sample; ``out.dxc`` is stage 1's).  Returns (status, saturation flags of the
    command): status 0, the law's failure status, or :data:`STATUS_NONFINITE_INPUT`.
    """
    eval_reference(lp.path, t, buf.refm)
    eta_t, nu_t = plant.pose(xp)
    eta, nu = measure(eta_t, nu_t, noise, k // lp.ctrl_every)
    u = out.u
    status = control_sample(t, eta, nu, attitude(eta[3], eta[4]), xc, xp, lp, buf, out)
    if status == 0 and not finite3(u):
        status = STATUS_NONFINITE_INPUT
    if status != 0:
        return status, 0
    sat = plant.allocate((u[0], u[1], u[2]), eta, nu, xp, lp.pp, buf.cmd, lp.h, cmd_sample)
    cmd = buf.cmd
    for i in range(cmd_sample.shape[0]):
        cmd[i] = cmd_sample[i]
    kc1, kc2, kc3, kc4 = out.dxc, rk.kc2, rk.kc3, rk.kc4
    for i in range(xc.shape[0]):
        kc2[i] = kc3[i] = kc4[i] = kc1[i]
    return 0, sat


@kernel_part("njit_noalloc(inline='always')")
def first_stage(t, xp, xc, lp, buf, rk, out):
    """RK4 stage 1 at (t, x) into ``rk.kp1`` and ``out``; return (status, flags, applied input, eta, e).

    The applied input (what the plant produces), the true pose and the virtual point's error to
    the reference are the values that are logged and enter the metrics.
    """
    att = plant_attitude(xp)
    status, flags = stage(t, xp, xc, att, lp, buf, rk.kp1, out, True)
    applied = plant.applied(xp, buf.cmd, lp.pp)
    eta, nu = plant.pose(xp)
    refm = buf.refm
    p1 = virtual_point(eta, att, lp.vp[VP.ell])
    e = (p1[0] - refm[0, 0], p1[1] - refm[0, 1], p1[2] - refm[0, 2])
    return status, flags, applied, eta, e


@kernel_part("njit_noalloc(inline='always')")
def advance(t, dt, xp, xc, lp, buf, rk, e, applied, eta, sat, acc, settings, t_late, reuse, outs):
    """The step's metrics at (t, x), then RK4 stages 2 to 4 and the state after the step in ``rk.xpn``, ``rk.xcn``.

    Stage 1 is in ``rk.kp1``, ``rk.kc1`` (:func:`first_stage`); ``outs`` are the law-output bundles
    of stages 2, 3 and 4 (on ``rk.kc2``, ``rk.kc3``, ``rk.kc4``), built once by the caller.  The path-following metrics are added when ``settings.si[SI.path_metrics]`` is set;
    ``t_late`` starts their second half.  Returns (controller status of the stages, failure cause
    of the state after the step): the caller takes the step (:func:`take_step`) when both are 0.
    """
    si, sf = settings.si, settings.sf
    t0, t1 = sf[SF.win_t0], sf[SF.win_t1]
    metrics_update(acc, t, dt, e, applied, t0, t1)
    saturation_update(acc, t, dt, sat, t0, t1)
    if si[SI.path_metrics] != 0:
        path_update(acc, t, dt, (eta[0], eta[1], eta[2]), lp.path, t0, t1, t_late)
    effort_update(acc, t, dt, plant.effort(xp, buf.cmd, lp.pp), t0, t1)
    kp1, kp2, kp3, kp4, kc1, kc2, kc3, kc4 = rk.kp1, rk.kp2, rk.kp3, rk.kp4, rk.kc1, rk.kc2, rk.kc3, rk.kc4
    xps, xcs, xpn, xcn = rk.xps, rk.xcs, rk.xpn, rk.xcn
    nxp, nxc = xp.shape[0], xc.shape[0]
    for i in range(nxp):
        xps[i] = xp[i] + 0.5 * dt * kp1[i]
    for i in range(nxc):
        xcs[i] = xc[i] + 0.5 * dt * kc1[i]
    status, _ = stage(t + 0.5 * dt, xps, xcs, plant_attitude(xps), lp, buf, kp2, outs[0], True)
    if status == 0:
        for i in range(nxp):
            xps[i] = xp[i] + 0.5 * dt * kp2[i]
        for i in range(nxc):
            xcs[i] = xc[i] + 0.5 * dt * kc2[i]
        status, _ = stage(t + 0.5 * dt, xps, xcs, plant_attitude(xps), lp, buf, kp3, outs[1], not reuse)
    if status == 0:
        for i in range(nxp):
            xps[i] = xp[i] + dt * kp3[i]
        for i in range(nxc):
            xcs[i] = xc[i] + dt * kc3[i]
        status, _ = stage(t + dt, xps, xcs, plant_attitude(xps), lp, buf, kp4, outs[2], True)
    if status != 0:
        return status, CAUSE_NONE
    for i in range(nxp):
        xpn[i] = xp[i] + dt / 6.0 * (kp1[i] + 2.0 * kp2[i] + 2.0 * kp3[i] + kp4[i])
    for i in range(nxc):
        xcn[i] = xc[i] + dt / 6.0 * (kc1[i] + 2.0 * kc2[i] + 2.0 * kc3[i] + kc4[i])
    return 0, state_cause(xpn, xcn, sf)


@kernel_part("njit_noalloc(inline='always')")
def take_step(xp, xc, rk):
    """Take the step :func:`advance` computed: x = (``rk.xpn``, ``rk.xcn``)."""
    xpn, xcn = rk.xpn, rk.xcn
    for i in range(xp.shape[0]):
        xp[i] = xpn[i]
    for i in range(xc.shape[0]):
        xc[i] = xcn[i]


@kernel_part("njit")
def log_row(log, row, t, xp, cmd, pp, tau, refm, e, aux, naux, dxp, vp):
    """Fill one logged row (:data:`~auvtrack.channels.LOG_ROW`); chi uses the nominal model with the produced input."""
    eta, nu = plant.pose(xp)
    log[row, LOG_ROW.t] = t
    for i in range(5):
        log[row, LOG_ROW.eta + i] = eta[i]
        log[row, LOG_ROW.nu + i] = nu[i]
    for i in range(3):
        log[row, LOG_ROW.tau + i] = tau[i]
        log[row, LOG_ROW.eta_d + i] = refm[0, i]
        log[row, LOG_ROW.e + i] = e[i]
    for i in range(naux):
        log[row, LOG_ROW.size + i] = aux[i]
    att = attitude(eta[3], eta[4])
    dnu_nom = nu_dot(att, nu, tau, (0.0, 0.0, 0.0, 0.0, 0.0), vp)
    chi = lumped_disturbance(att, plant.accel5(dxp), dnu_nom, vp[VP.ell])
    col = LOG_ROW.size + naux
    log[row, col], log[row, col + 1], log[row, col + 2] = chi
    plant.log_extra(xp, cmd, pp, log, row, col + 3)


@kernel_part("njit(nogil=True)")
def run(pb, cb, env, ref_p, settings, out):
    """Integrate the closed loop; return (cause, rows_logged, t_stop).

    ``out.log`` has shape (n_rows, len(channels)) (:func:`~auvtrack.channels.channel_names`);
    ``out.acc`` is the metrics accumulator (initialised by :func:`~auvtrack.metrics.metrics_init`).
    """
    si, sf = settings.si, settings.sf
    log, acc, fail_state, info = out.log, out.acc, out.fail_state, out.info
    pp, cp, vp = pb.pp, cb.cp, cb.vp
    nxp, nxc = pb.x0.shape[0], cb.x0.shape[0]
    n_steps, log_every, ctrl_every = si[SI.n_steps], si[SI.log_every], si[SI.ctrl_every]
    naux = si[SI.n_aux]
    dt = sf[SF.dt]
    xp, xc = pb.x0.copy(), cb.x0.copy()
    # the state after a step (rk.xpn, rk.xcn) is checked before it is taken
    rk = Rk4(np.zeros(nxp), np.zeros(nxp), np.zeros(nxp), np.zeros(nxp), np.zeros(nxc), np.zeros(nxc), np.zeros(nxc),
             np.zeros(nxc), np.empty(nxp), np.empty(nxc), np.empty(nxp), np.empty(nxc))
    cmd, cmd_sample = np.zeros(plant.N_CMD), np.zeros(plant.N_CMD)
    buf = Buffers(np.zeros((3, 3)), np.zeros(WORK_SIZE), np.zeros(SCRATCH_SIZE), cmd)
    refm = buf.refm
    lp = Loop(pp, cp, vp, ref_p, env.rows, env.current, ctrl_every, ctrl_every * dt)
    sat = 0  # saturation flags of the command in force
    tau1, tau = np.zeros(3), np.zeros(3)
    aux1, aux = np.zeros(max(naux, 1)), np.zeros(max(naux, 1))
    # the law's outputs of each RK4 stage, bundled once: a bundle built in the loop costs an atomic
    # reference-count increment and decrement per array at every stage (run is compiled with the runtime)
    out1 = LawOutputs(tau1, rk.kc1, aux1)
    outs = (LawOutputs(tau, rk.kc2, aux), LawOutputs(tau, rk.kc3, aux), LawOutputs(tau, rk.kc4, aux))
    reuse = state_free_disturbance(env.rows)  # stage 3 may reuse stage 2's reference and omega
    t_late = 0.5 * (sf[SF.win_t0] + min(sf[SF.win_t1], n_steps * dt))  # second half of the planned window
    row = 0
    info[INFO_STEPS] = 0
    for k in range(n_steps + 1):
        t = k * dt
        if (k & (STOP_POLL - 1)) == 0 and info[INFO_STOP] != 0:
            record_stop(xp, xc, xp, xc, fail_state)
            return CAUSE_INTERRUPTED, row, t
        if ctrl_every > 0 and k % ctrl_every == 0:  # sampled-data: measure, compute, allocate, hold
            status, sat_k = sample(t, k, xp, xc, lp, buf, env.noise, out1, rk, cmd_sample)
            if status != 0:
                record_stop(xp, xc, xp, xc, fail_state)
                info[INFO_STATUS] = status
                return CAUSE_CONTROLLER, row, t
            sat = sat_k
        # stage 1 at (t, x): also the values that are logged and enter the metrics
        status, flags, applied, eta, e = first_stage(t, xp, xc, lp, buf, rk, out1)
        if ctrl_every == 0:
            sat = flags
        if status == 0 and ctrl_every == 0 and not finite3(tau1):
            status = STATUS_NONFINITE_INPUT
        if status != 0:
            record_stop(xp, xc, xp, xc, fail_state)
            info[INFO_STATUS] = status
            return CAUSE_CONTROLLER, row, t
        if k % log_every == 0 and row < log.shape[0]:
            log_row(log, row, t, xp, cmd, pp, applied, refm, e, aux1, naux, rk.kp1, vp)
            row += 1
        if k == n_steps:
            break
        status, cause = advance(t, dt, xp, xc, lp, buf, rk, e, applied, eta, sat, acc, settings, t_late, reuse,
                                outs)
        if status != 0:
            record_stop(xp, xc, xp, xc, fail_state)
            info[INFO_STATUS] = status
            return CAUSE_CONTROLLER, row, t
        info[INFO_STEPS] = k + 1
        if cause != CAUSE_NONE:
            record_stop(rk.xpn, rk.xcn, xp, xc, fail_state)
            return cause, row, t + dt
        take_step(xp, xc, rk)
    return CAUSE_NONE, row, n_steps * dt


@kernel_part("njit(nogil=True)")
def run_row(ins, i, ncols, outs):
    """:func:`run` of row ``i`` of ``ins`` (:class:`Stacked`) into row ``i`` of ``outs`` (:class:`StackedOutputs`)."""
    log = np.empty((0, ncols))
    cause, _, t_stop = run(PlantBundle(ins.pp[i], ins.xp0[i]), ControllerBundle(ins.cp[i], ins.xc0[i], ins.vp[i]),
                           EnvironmentBundle(ins.rows[i], ins.current[i], ins.noise[i]), ins.path[i],
                           Settings(ins.si[i], ins.sf[i]), Outputs(log, outs.acc[i], outs.fail_state[i], outs.info[i]))
    outs.cause[i] = cause
    outs.t_stop[i] = t_stop


@kernel_part("njit(nogil=True, parallel=True)")
def run_many(ins, ncols, outs):
    """:func:`run` of ``len(ins.pp)`` runs of identical array shapes in a ``prange`` loop, metrics only.

    ``ins`` is a :class:`Stacked`, ``outs`` a :class:`StackedOutputs` (its ``log`` unused).  The loop
    body is one call: built inline, the bundles of a run lose its settings under Numba 0.68's
    parallel lowering (every run integrated with ``dt = 0``; ``tests/batch/test_batch.py`` catches it).
    """
    for i in prange(ins.pp.shape[0]):
        run_row(ins, i, ncols, outs)


@kernel_part("njit(nogil=True)", lanes=True)
def run_lanes(ins, outs, counts, b0, b1):
    """:func:`run` of LANES runs at once, one per lane of a SIMD register, for the blocks b0 .. b1 - 1.

    Block ``b`` of every array of ``ins`` (:class:`Stacked`) and ``outs`` (:class:`StackedOutputs`)
    holds ``counts[b]`` runs along its last axis (length LANES; the lanes beyond ``counts[b]`` are
    padding and never written back).  ``run__lanes`` is the lane form of :func:`run`
    (:mod:`auvtrack.engine.lanes`): the same loop, each run's branches taken in its own lane, a run
    that stops leaving its lane with its own cause and time.
    """
    for b in range(b0, b1):
        m = first_lanes(counts[b], LANES)
        out = Outputs(as_lanes(outs.log[b], LANES), as_lanes(outs.acc[b], LANES),
                      as_lanes(outs.fail_state[b], LANES), as_lanes(outs.info[b], LANES))
        cause, _, t_stop = run__lanes(PlantBundle(as_lanes(ins.pp[b], LANES), as_lanes(ins.xp0[b], LANES)),
                                      ControllerBundle(as_lanes(ins.cp[b], LANES), as_lanes(ins.xc0[b], LANES),
                                                       as_lanes(ins.vp[b], LANES)),
                                      EnvironmentBundle(as_lanes(ins.rows[b], LANES), as_lanes(ins.current[b], LANES),
                                                        as_lanes(ins.noise[b], LANES)),
                                      as_lanes(ins.path[b], LANES),
                                      Settings(as_lanes(ins.si[b], LANES), as_lanes(ins.sf[b], LANES)), out, m)
        for k in range(counts[b]):
            outs.cause[b, k] = get_lane(cause, k)
            outs.t_stop[b, k] = get_lane(t_stop, k)
