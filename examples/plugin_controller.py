"""A plug-in controller for auvtrack: PD on the virtual-point error with feed-forward.

Use it from any folder, without touching the package:

    [controller]
    kind = "plugin"
    module = "plugin_controller.py"      # relative to the scenario file, or absolute
    params = { kp = 9.0, kd = 6.0 }      # validated by Params below

The law, per axis i (the same error e = eta1 - eta_d and nominal model as the built-ins):

    a_i = -kp e_i - kd e_dot_i        (m/s^2, the commanded error acceleration)
    tau = the nominal input that makes e_ddot = a on the nominal model

The input map feeds the reference acceleration forward (e_ddot contains -eta_d_ddot), so on the
disturbance-free nominal plant e obeys e'' + kd e' + kp e = 0 (the defaults: a double pole at
-3 rad/s); on Section 4 the lumped disturbance chi leaves an error of about |chi| / kp.  The contract is in docs/plugins.md.
"""
import numpy as np
from pydantic import Field

from auvtrack.control.plugin import (CompiledController, ControllerParamsBase, error_state_forces,
                                     input_for_accel_forces, njit)

AUX_NAMES = ("a_x", "a_y", "a_z")  # logged channels (the commanded e_ddot)


class Params(ControllerParamsBase):
    """The ``params`` table of ``[controller]``."""

    kp: float = Field(9.0, gt=0, description="proportional gain, 1/s^2")
    kd: float = Field(6.0, gt=0, description="derivative gain, 1/s")


@njit
def control(t, eta, nu, att, xc, refm, vp, cp, tau, dxc, aux, work):
    """Compiled law: writes tau (N, N m) and the logged channels; returns 0 (ok)."""
    e, ed, f, g = error_state_forces(eta, att, nu, refm, vp)
    kp, kd = cp[0], cp[1]
    a = (-kp * e[0] - kd * ed[0], -kp * e[1] - kd * ed[1], -kp * e[2] - kd * ed[2])
    tau[0], tau[1], tau[2] = input_for_accel_forces(att, vp, f, a, g)
    aux[0], aux[1], aux[2] = a
    return 0


def setup(scenario, ctx):
    """Pack the gains for ``control``; no internal state."""
    p = scenario.controller  # a validated Params
    return CompiledController(cp=np.array([p.kp, p.kd]), xc0=np.zeros(0), aux_names=AUX_NAMES)
