"""Compiled dispatch from a controller code to its ``control`` function.

Every controller's compiled law has the signature

    control(t, eta, nu, xc, refm, vp, cp, tau, dxc, aux, work) -> int status

=======  ==============================================================================
t        time (s)
eta, nu  measured state (5,) each (see :mod:`auvtrack.plant.kinematics`)
xc       controller internal state (read only), shape (nc,)
refm     (3, 3) rows eta_d, eta_d_dot, eta_d_ddot
vp       packed *nominal* vehicle parameters (the controller never sees the true plant)
cp       packed controller parameters
tau      output (3,): [tau_u (N), tau_q (N m), tau_r (N m)]
dxc      output (nc,): time derivative of the internal state
aux      output: extra logged channels (the controller's ``aux_names``)
work     scratch (float64, length WORK_SIZE); no allocation in the hot path
status   0 = ok, otherwise a code of :data:`CONTROLLER_STATUS`
=======  ==============================================================================

Numba cannot cache a loop that receives a function as an argument, so the engine calls this one
module-level switch; registering a controller adds one branch here.
"""
from __future__ import annotations

from .._jit import njit
from . import ftsmc, fxtntsmc, open_loop

WORK_SIZE = 512

CONTROLLER_STATUS = {
    1: "envelope violated: |e_i| >= rho_i (the error transformation is undefined)",
    2: "start on or outside the envelope and widen_start is off",
    3: "controller produced a non-finite input",
}


@njit
def control(code, t, eta, nu, xc, refm, vp, cp, tau, dxc, aux, work):
    """Evaluate controller ``code``; unknown codes return status 99."""
    if code == ftsmc.CODE:
        return ftsmc.control(t, eta, nu, xc, refm, vp, cp, tau, dxc, aux, work)
    if code == fxtntsmc.CODE:
        return fxtntsmc.control(t, eta, nu, xc, refm, vp, cp, tau, dxc, aux, work)
    if code == open_loop.CODE:
        return open_loop.control(t, eta, nu, xc, refm, vp, cp, tau, dxc, aux, work)
    return 99
