"""Compiled closed loop: plant, environment, reference and controller under fixed-step RK4.

State X = [eta (5), nu (5), xc (nc)]: the plant and the controller's internal states (adaptive
weights, envelope filters) are integrated together.  Two modes:

* continuous (``ctrl_every = 0``): the controller is evaluated at every RK4 stage;
* sampled-data (``ctrl_every = k``): the controller runs every k steps on the measured state and
  its input tau and internal-state derivative are held (zero-order hold) until the next sample.

Actuators and sensors (:mod:`auvtrack.plant.actuators`, :mod:`auvtrack.environment.sensors`):
the applied input is the command saturated to ``|tau_j| <= tau_max_j`` (both modes); in
sampled-data mode it is also rate limited between samples (from tau = 0 at t = 0), and the
controller sees the state plus row k of the seeded noise table ``noise`` at sample k.  Logs and
metrics always use the true state and the applied input.

One row is logged every ``log_every`` steps into a preallocated array (O(N) in total).  After
every step the state is checked; a failure stops the run at once and keeps what was logged.
Integer settings ``si`` and float settings ``sf`` use the index constants below.

Performance note: arrays are passed whole and indexed, never sliced, in the hot path (a slice
is a reference-counted view whose atomic inc/decrements cost more than the arithmetic).
"""
from __future__ import annotations

import math

import numpy as np
from numba import literally

from .._jit import njit, njit_noalloc
from ..control import ftsmc, fxtntsmc, open_loop
from ..control.dispatch import NX_PLANT, WORK_SIZE, control
from ..control.tracking import lumped_disturbance
from ..environment import eval_disturbance
from ..environment.layout import KIND_PAPER, KIND_PULSE
from ..environment.sensors import measure
from ..plant.actuators import ACT_SIZE, rate_limit, saturate
from ..plant.dynamics import nu_dot
from ..plant.kinematics import attitude, eta_dot, virtual_point
from ..plant.params import ELL
from ..reference import eval_reference
from .metrics import metrics_update

SI_NSTEPS, SI_LOG_EVERY, SI_CTRL_EVERY, SI_CODE, SI_NAUX, SI_NC = range(6)
SI_SIZE = 6
SF_DT, SF_THETA_LIM, SF_STATE_LIM, SF_WIN_T0, SF_WIN_T1, SF_ACT = range(6)
SF_SIZE = SF_ACT + ACT_SIZE  # sf[SF_ACT:] = actuator limits [tau_max (3), rate_max (3)]

# logged row: t, eta(5), nu(5), tau(3), eta_d(3), e(3), aux(naux), chi(3)
N_BASE_COLS = 20

CAUSE_NONE, CAUSE_NONFINITE, CAUSE_PITCH, CAUSE_STATE_LIMIT = 0, 1, 2, 3
CAUSE_CONTROLLER = 10  # + controller status code
CAUSES = {
    CAUSE_NONFINITE: "non-finite state (NaN or Inf)",
    CAUSE_PITCH: "pitch limit exceeded (|theta| beyond sim.theta_limit)",
    CAUSE_STATE_LIMIT: "state limit exceeded (divergence, |state| > sim.state_limit)",
}
STATUS_NONFINITE_INPUT = 3
assert (ftsmc.CODE, fxtntsmc.CODE, open_loop.CODE) == (1, 2, 3), "update run_kernel's branches"


@njit_noalloc
def plant_state(X):
    """(eta, nu) tuples of the plant part of X."""
    return (X[0], X[1], X[2], X[3], X[4]), (X[5], X[6], X[7], X[8], X[9])


@njit_noalloc
def closed_loop_rhs(code, t, X, ctrl_every, nx, cp, vp_nom, vp_true, ref_p, d_rows, d_cur, hold, dX, tau, aux,
                    refm, omega, work, att, fresh, sf):
    """Write dX/dt; return 0 or a controller status.  ``hold`` = [tau (3), dxc] in sampled mode.

    ``att`` is :func:`attitude` of X (the caller computes it once per stage).  With ``fresh``
    false the reference ``refm`` and disturbance ``omega`` of the previous call are reused: the
    engine passes false only for the second of two stages at the same time whose disturbance
    does not depend on the state (RK4 stages 2 and 3), so the values are the same numbers.
    """
    literally(code)
    eta, nu = plant_state(X)
    if fresh:
        eval_reference(ref_p, t, refm)
    if ctrl_every == 0:
        status = control(code, t, eta, nu, att, X, refm, vp_nom, cp, tau, dX, aux, work)
        if status != 0:
            return status
        tau[0], tau[1], tau[2] = saturate((tau[0], tau[1], tau[2]), sf, SF_ACT)
    else:
        tau[0], tau[1], tau[2] = hold[0], hold[1], hold[2]
        for i in range(NX_PLANT, nx):
            dX[i] = hold[3 + i - NX_PLANT]
    if fresh:
        eval_disturbance(d_rows, d_cur, t, eta, nu, vp_true, omega)
    dX[0], dX[1], dX[2], dX[3], dX[4] = eta_dot(att, nu)
    dX[5], dX[6], dX[7], dX[8], dX[9] = nu_dot(att, nu, (tau[0], tau[1], tau[2]),
                                               (omega[0], omega[1], omega[2], omega[3], omega[4]), vp_true)
    return 0


@njit
def state_free_disturbance(d_rows):
    """True when omega depends on time only (paper and pulse components), not on the state."""
    for k in range(d_rows.shape[0]):
        if d_rows[k, 0] != KIND_PAPER and d_rows[k, 0] != KIND_PULSE:
            return False
    return True


@njit
def _log_row(log, row, t, X, tau, refm, e, aux, naux, dX, vp_nom):
    """Fill one logged row (see N_BASE_COLS); chi uses the nominal model with the same input."""
    log[row, 0] = t
    for i in range(10):
        log[row, 1 + i] = X[i]
    for i in range(3):
        log[row, 11 + i] = tau[i]
        log[row, 14 + i] = refm[0, i]
        log[row, 17 + i] = e[i]
    for i in range(naux):
        log[row, 20 + i] = aux[i]
    eta, nu = plant_state(X)
    att = attitude(eta[3], eta[4])
    dnu_nom = nu_dot(att, nu, (tau[0], tau[1], tau[2]), (0.0, 0.0, 0.0, 0.0, 0.0), vp_nom)
    chi = lumped_disturbance(att, (dX[5], dX[6], dX[7], dX[8], dX[9]), dnu_nom, vp_nom[ELL])
    log[row, 20 + naux], log[row, 21 + naux], log[row, 22 + naux] = chi


@njit_noalloc(inline="always")
def _state_cause(X, theta_lim, state_lim):
    """Failure cause of a state (precedence: non-finite, pitch, state limit), one pass."""
    nonfinite = over = False
    for i in range(X.shape[0]):
        x = X[i]
        if not math.isfinite(x):
            nonfinite = True
        elif abs(x) > state_lim:
            over = True
    if nonfinite:
        return CAUSE_NONFINITE
    if abs(X[3]) > theta_lim:
        return CAUSE_PITCH
    if over:
        return CAUSE_STATE_LIMIT
    return CAUSE_NONE


@njit_noalloc
def _finite3(v):
    return math.isfinite(v[0]) and math.isfinite(v[1]) and math.isfinite(v[2])


@njit
def _fail(status, X, fail_state):
    for i in range(X.shape[0]):
        fail_state[i] = X[i]
    return status


@njit(nogil=True)
def run_kernel(code, X0, si, sf, cp, vp_nom, vp_true, ref_p, d_rows, d_cur, noise, log, acc, fail_state):
    """Integrate the closed loop of controller ``code``; return (cause, rows_logged, t_stop).

    The one run-time switch on ``code``: each branch calls :func:`integrate` with a constant,
    so every controller gets its own specialised, cached loop (registering a controller adds
    one branch here and one in :mod:`auvtrack.control.dispatch`).  ``log`` has shape
    (n_rows, N_BASE_COLS + naux + 3); ``acc`` is the metrics accumulator; on failure the
    state at the stop is copied into ``fail_state``.
    """
    if code == 1:  # ftsmc.CODE (a literal: numba needs it in the source)
        return integrate(1, X0, si, sf, cp, vp_nom, vp_true, ref_p, d_rows, d_cur, noise, log, acc, fail_state)
    if code == 2:  # fxtntsmc.CODE (a literal: numba needs it in the source)
        return integrate(2, X0, si, sf, cp, vp_nom, vp_true, ref_p, d_rows, d_cur, noise, log, acc, fail_state)
    if code == 3:  # open_loop.CODE (a literal: numba needs it in the source)
        return integrate(3, X0, si, sf, cp, vp_nom, vp_true, ref_p, d_rows, d_cur, noise, log, acc, fail_state)
    return CAUSE_CONTROLLER + 99, 0, 0.0


@njit(nogil=True)
def integrate(code, X0, si, sf, cp, vp_nom, vp_true, ref_p, d_rows, d_cur, noise, log, acc, fail_state):
    """The RK4 loop of :func:`run_kernel` for one controller; ``code`` is a compile-time literal.

    ``numba.literally`` makes the controller dispatch fold away (a run-time switch per stage
    costs ~0.3 us); calling this from Python directly would re-type it on every call (~0.1 s),
    which is why :func:`run_kernel` is the entry point.
    """
    literally(code)
    nx = X0.shape[0]
    n_steps, log_every, ctrl_every = si[SI_NSTEPS], si[SI_LOG_EVERY], si[SI_CTRL_EVERY]
    naux = si[SI_NAUX]
    dt = sf[SF_DT]
    X = X0.copy()
    Xs = np.empty(nx)
    k1, k2, k3, k4 = np.zeros(nx), np.zeros(nx), np.zeros(nx), np.zeros(nx)
    hold = np.zeros(3 + nx - NX_PLANT)
    tau1, tau = np.zeros(3), np.zeros(3)
    aux1, aux = np.zeros(max(naux, 1)), np.zeros(max(naux, 1))
    refm = np.zeros((3, 3))
    omega = np.zeros(5)
    work = np.zeros(WORK_SIZE)
    reuse = state_free_disturbance(d_rows)  # stage 3 may reuse stage 2's reference and omega
    row = 0
    for k in range(n_steps + 1):
        t = k * dt
        if ctrl_every > 0 and k % ctrl_every == 0:  # sampled-data: measure, compute, hold
            eval_reference(ref_p, t, refm)
            eta, nu = measure(X, noise, k // ctrl_every)
            status = control(code, t, eta, nu, attitude(eta[3], eta[4]), X, refm, vp_nom, cp, tau1, k1, aux1, work)
            if status == 0 and not _finite3(tau1):
                status = STATUS_NONFINITE_INPUT
            if status != 0:
                return _fail(CAUSE_CONTROLLER + status, X, fail_state), row, t
            cmd = saturate((tau1[0], tau1[1], tau1[2]), sf, SF_ACT)
            hold[0], hold[1], hold[2] = rate_limit(cmd, (hold[0], hold[1], hold[2]), sf, SF_ACT, ctrl_every * dt)
            for i in range(NX_PLANT, nx):
                hold[3 + i - NX_PLANT] = k1[i]
        # stage 1 at (t, X): also the values that are logged and enter the metrics
        att = attitude(X[3], X[4])
        status = closed_loop_rhs(code, t, X, ctrl_every, nx, cp, vp_nom, vp_true, ref_p, d_rows, d_cur, hold,
                                 k1, tau1, aux1, refm, omega, work, att, True, sf)
        if status == 0 and not _finite3(tau1):
            status = STATUS_NONFINITE_INPUT
        if status != 0:
            return _fail(CAUSE_CONTROLLER + status, X, fail_state), row, t
        eta, nu = plant_state(X)
        p1 = virtual_point(eta, att, vp_nom[ELL])
        e = (p1[0] - refm[0, 0], p1[1] - refm[0, 1], p1[2] - refm[0, 2])
        if k % log_every == 0 and row < log.shape[0]:
            _log_row(log, row, t, X, tau1, refm, e, aux1, naux, k1, vp_nom)
            row += 1
        if k == n_steps:
            break
        metrics_update(acc, t, dt, e, (tau1[0], tau1[1], tau1[2]), sf[SF_WIN_T0], sf[SF_WIN_T1])
        for i in range(nx):
            Xs[i] = X[i] + 0.5 * dt * k1[i]
        status = closed_loop_rhs(code, t + 0.5 * dt, Xs, ctrl_every, nx, cp, vp_nom, vp_true, ref_p, d_rows, d_cur,
                                 hold, k2, tau, aux, refm, omega, work, attitude(Xs[3], Xs[4]), True, sf)
        if status == 0:
            for i in range(nx):
                Xs[i] = X[i] + 0.5 * dt * k2[i]
            status = closed_loop_rhs(code, t + 0.5 * dt, Xs, ctrl_every, nx, cp, vp_nom, vp_true, ref_p, d_rows,
                                     d_cur, hold, k3, tau, aux, refm, omega, work, attitude(Xs[3], Xs[4]), not reuse, sf)
        if status == 0:
            for i in range(nx):
                Xs[i] = X[i] + dt * k3[i]
            status = closed_loop_rhs(code, t + dt, Xs, ctrl_every, nx, cp, vp_nom, vp_true, ref_p, d_rows, d_cur,
                                     hold, k4, tau, aux, refm, omega, work, attitude(Xs[3], Xs[4]), True, sf)
        if status != 0:
            return _fail(CAUSE_CONTROLLER + status, X, fail_state), row, t
        for i in range(nx):
            X[i] += dt / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i])
        cause = _state_cause(X, sf[SF_THETA_LIM], sf[SF_STATE_LIM])
        if cause != CAUSE_NONE:
            return _fail(cause, X, fail_state), row, t + dt
    return CAUSE_NONE, row, n_steps * dt
