"""Compiled dispatch from a controller code to its ``control`` function.

Every controller's compiled law has the signature

    control(t, eta, nu, att, X, refm, vp, cp, tau, dX, aux, work) -> int status

=======  ==============================================================================
t        time (s)
eta, nu  measured state, 5-tuples (see :mod:`auvtrack.plant.kinematics`)
att      attitude(eta[3], eta[4]) = (cos theta, sin theta, cos psi, sin psi) of the measured
         state, computed by the engine (in continuous mode the plant's right-hand side shares it)
X        full state; the controller's internal state is X[NX_PLANT:] (read only)
refm     (3, 3) rows eta_d, eta_d_dot, eta_d_ddot
vp       packed *nominal* vehicle parameters (the controller never sees the true plant)
cp       packed controller parameters
tau      output (3,): [tau_u (N), tau_q (N m), tau_r (N m)]
dX       output: the controller writes d/dt of its internal state into dX[NX_PLANT:]
aux      output: extra logged channels (the controller's ``aux_names``)
work     scratch (float64, length WORK_SIZE) for variable-size temporaries
status   0 = ok, otherwise a code of :data:`CONTROLLER_STATUS`
=======  ==============================================================================

Numba cannot cache a loop that receives a function as an argument, so the engine calls this one
module-level switch with a compile-time literal code (the switch folds away); registering a
controller adds one branch here and one in ``engine.run_kernel``.  Arrays are passed whole and indexed: slicing in the hot
path creates reference-counted views that cost more than the arithmetic.
"""
from __future__ import annotations

from numba import literally

from .._jit import njit_noalloc
from . import ftsmc, fxtntsmc, open_loop
from .dispatch_layout import NX_PLANT, WORK_SIZE  # noqa: F401  (re-exported)


CONTROLLER_STATUS = {
    1: "envelope violated: |e_i| >= rho_i (the error transformation is undefined)",
    2: "start on or outside the envelope and widen_start is off",
    3: "controller produced a non-finite input",
}


@njit_noalloc
def control(code, t, eta, nu, att, X, refm, vp, cp, tau, dX, aux, work):
    """Evaluate controller ``code`` (a compile-time literal); unknown codes return status 99."""
    literally(code)
    if code == ftsmc.CODE:
        return ftsmc.control(t, eta, nu, att, X, refm, vp, cp, tau, dX, aux, work)
    if code == fxtntsmc.CODE:
        return fxtntsmc.control(t, eta, nu, att, X, refm, vp, cp, tau, dX, aux, work)
    if code == open_loop.CODE:
        return open_loop.control(t, eta, nu, att, X, refm, vp, cp, tau, dX, aux, work)
    return 99
