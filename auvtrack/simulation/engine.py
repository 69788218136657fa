"""Compiled closed loop: plant, environment, reference and controller under fixed-step RK4.

State X = [eta (5), nu (5), xc (nc)]: the plant and the controller's internal states (adaptive
weights, envelope filters) are integrated together.  Two modes:

* continuous (``ctrl_every = 0``): the controller is evaluated at every RK4 stage;
* sampled-data (``ctrl_every = k``): the controller runs every k steps on the measured state and
  its input tau and internal-state derivative are held (zero-order hold) until the next sample.

One row is logged every ``log_every`` steps into a preallocated array (O(N) in total).  After
every step the state is checked; a failure stops the run at once and keeps what was logged.

Integer settings ``si`` and float settings ``sf`` use the index constants below.
"""
from __future__ import annotations

import math

import numpy as np

from .._jit import njit
from ..control.dispatch import WORK_SIZE, control
from ..control.tracking import lumped_disturbance
from ..environment import eval_disturbance
from ..plant.dynamics import nu_dot
from ..plant.kinematics import eta_dot, virtual_point
from ..plant.params import ELL
from ..reference import eval_reference
from .metrics import metrics_update

SI_NSTEPS, SI_LOG_EVERY, SI_CTRL_EVERY, SI_CODE, SI_NAUX, SI_NC = range(6)
SI_SIZE = 6
SF_DT, SF_THETA_LIM, SF_STATE_LIM, SF_WIN_T0, SF_WIN_T1 = range(5)
SF_SIZE = 5

NX_PLANT = 10
# logged row: t, eta(5), nu(5), tau(3), eta_d(3), e(3), aux(naux), chi(3)
N_BASE_COLS = 20

CAUSE_NONE, CAUSE_NONFINITE, CAUSE_PITCH, CAUSE_STATE_LIMIT = 0, 1, 2, 3
CAUSE_CONTROLLER = 10  # + controller status code
CAUSES = {
    CAUSE_NONFINITE: "non-finite state (NaN or Inf)",
    CAUSE_PITCH: "pitch limit exceeded (|theta| beyond sim.theta_limit)",
    CAUSE_STATE_LIMIT: "state limit exceeded (divergence, |state| > sim.state_limit)",
}


@njit
def closed_loop_rhs(t, X, si, cp, vp_nom, vp_true, ref_p, d_rows, d_cur, hold, dX, tau, aux, refm, omega, work):
    """Write dX/dt; return 0 or a controller status.  ``hold`` = [tau(3), dxc] in sampled mode."""
    eta = X[0:5]
    nu = X[5:10]
    eval_reference(ref_p, t, refm)
    nc = si[SI_NC]
    if si[SI_CTRL_EVERY] == 0:
        status = control(si[SI_CODE], t, eta, nu, X[10:], refm, vp_nom, cp, tau, dX[10:], aux, work)
        if status != 0:
            return status
    else:
        for i in range(3):
            tau[i] = hold[i]
        for i in range(nc):
            dX[10 + i] = hold[3 + i]
    eval_disturbance(d_rows, d_cur, t, eta, nu, vp_true, omega)
    eta_dot(eta, nu, dX[0:5])
    nu_dot(eta, nu, tau, omega, vp_true, dX[5:10])
    return 0


@njit
def _log_row(row, t, X, tau, refm, e, aux, naux, dnu_true, vp_nom, omega, dnu_nom):
    """Fill one logged row (see N_BASE_COLS); chi uses the nominal model with the same input."""
    row[0] = t
    for i in range(10):
        row[1 + i] = X[i]
    for i in range(3):
        row[11 + i] = tau[i]
        row[14 + i] = refm[0, i]
        row[17 + i] = e[i]
    for i in range(naux):
        row[20 + i] = aux[i]
    for i in range(5):
        omega[i] = 0.0
    nu_dot(X[0:5], X[5:10], tau, omega, vp_nom, dnu_nom)
    lumped_disturbance(X[0:5], dnu_true, dnu_nom, vp_nom[ELL], row[20 + naux : 23 + naux])


@njit
def _state_cause(X, theta_lim, state_lim):
    for i in range(X.shape[0]):
        if not math.isfinite(X[i]):
            return CAUSE_NONFINITE
    if abs(X[3]) > theta_lim:
        return CAUSE_PITCH
    for i in range(X.shape[0]):
        if abs(X[i]) > state_lim:
            return CAUSE_STATE_LIMIT
    return CAUSE_NONE


@njit
def _finite3(v):
    return math.isfinite(v[0]) and math.isfinite(v[1]) and math.isfinite(v[2])


@njit
def run_kernel(X0, si, sf, cp, vp_nom, vp_true, ref_p, d_rows, d_cur, log, acc, fail_state):
    """Integrate the closed loop; return (cause, rows_logged, t_stop).

    ``log`` has shape (n_rows, N_BASE_COLS + naux + 3); ``acc`` is the metrics accumulator;
    on failure the state at the stop is copied into ``fail_state``.
    """
    nx = X0.shape[0]
    n_steps, log_every, ctrl_every = si[SI_NSTEPS], si[SI_LOG_EVERY], si[SI_CTRL_EVERY]
    naux, nc = si[SI_NAUX], si[SI_NC]
    dt = sf[SF_DT]
    X = X0.copy()
    Xs = np.empty(nx)
    K = np.zeros((4, nx))
    hold = np.zeros(3 + nc)
    tau1 = np.zeros(3)
    tau = np.zeros(3)
    aux1 = np.zeros(max(naux, 1))
    aux = np.zeros(max(naux, 1))
    refm = np.zeros((3, 3))
    omega = np.zeros(5)
    work = np.zeros(WORK_SIZE)
    logwork = np.zeros(5)
    e = np.zeros(3)
    p1 = np.zeros(3)
    row = 0
    for k in range(n_steps + 1):
        t = k * dt
        # controller sample (sampled-data mode): measured state, zero-order hold
        if ctrl_every > 0 and k % ctrl_every == 0:
            eval_reference(ref_p, t, refm)
            status = control(si[SI_CODE], t, X[0:5], X[5:10], X[10:], refm, vp_nom, cp, tau1, hold[3:], aux1, work)
            if status == 0 and not _finite3(tau1):
                status = 3
            if status != 0:
                fail_state[:] = X
                return CAUSE_CONTROLLER + status, row, t
            for i in range(3):
                hold[i] = tau1[i]
        # stage 1 at (t, X): also the values that are logged and enter the metrics
        status = closed_loop_rhs(t, X, si, cp, vp_nom, vp_true, ref_p, d_rows, d_cur, hold, K[0], tau1, aux1, refm, omega, work)
        if status == 0 and not _finite3(tau1):
            status = 3
        if status != 0:
            fail_state[:] = X
            return CAUSE_CONTROLLER + status, row, t
        virtual_point(X[0:5], vp_nom[ELL], p1)
        for i in range(3):
            e[i] = p1[i] - refm[0, i]
        if k % log_every == 0 and row < log.shape[0]:
            _log_row(log[row], t, X, tau1, refm, e, aux1, naux, K[0, 5:10], vp_nom, omega, logwork)
            row += 1
        if k == n_steps:
            break
        metrics_update(acc, t, dt, e, tau1, sf[SF_WIN_T0], sf[SF_WIN_T1])
        # stages 2-4
        for i in range(nx):
            Xs[i] = X[i] + 0.5 * dt * K[0, i]
        status = closed_loop_rhs(t + 0.5 * dt, Xs, si, cp, vp_nom, vp_true, ref_p, d_rows, d_cur, hold, K[1], tau, aux, refm, omega, work)
        if status == 0:
            for i in range(nx):
                Xs[i] = X[i] + 0.5 * dt * K[1, i]
            status = closed_loop_rhs(t + 0.5 * dt, Xs, si, cp, vp_nom, vp_true, ref_p, d_rows, d_cur, hold, K[2], tau, aux, refm, omega, work)
        if status == 0:
            for i in range(nx):
                Xs[i] = X[i] + dt * K[2, i]
            status = closed_loop_rhs(t + dt, Xs, si, cp, vp_nom, vp_true, ref_p, d_rows, d_cur, hold, K[3], tau, aux, refm, omega, work)
        if status != 0:
            fail_state[:] = X
            return CAUSE_CONTROLLER + status, row, t
        for i in range(nx):
            X[i] += dt / 6.0 * (K[0, i] + 2.0 * K[1, i] + 2.0 * K[2, i] + K[3, i])
        cause = _state_cause(X, sf[SF_THETA_LIM], sf[SF_STATE_LIM])
        if cause != CAUSE_NONE:
            fail_state[:] = X
            return cause, row, t + dt
    return CAUSE_NONE, row, n_steps * dt
