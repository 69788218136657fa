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

from auvtrack.control.plugin import (CompiledController, ControllerParamsBase, error_state_forces,
                                     input_for_accel_forces, njit, packed_layout, tunable)

AUX_NAMES = ("a_x", "a_y", "a_z")  # logged channels (the commanded e_ddot)
GAINS = packed_layout("PDGains", kp=1, kd=1)  # the packed gains: offsets generated from the names


class Params(ControllerParamsBase):
    """The ``params`` table of ``[controller]``."""

    kp: float = tunable(9.0, 0.01, 100.0, log=True, gt=0, description="proportional gain, 1/s^2")
    kd: float = tunable(6.0, 0.1, 50.0, log=True, gt=0, description="derivative gain, 1/s")


@njit
def control(t, y, xc, args, out):
    """Compiled law: writes tau (N, N m) into out.u and the logged channels; returns 0 (ok).

    y: the measured state (y.eta, y.nu, y.att); args: the reference rows (args.ref), the gains
    (args.cp), the nominal vehicle (args.vp), ...; out: out.u, out.dxc, out.aux
    (docs/plugins.md lists every field).
    """
    e, ed, f, g = error_state_forces(y.eta, y.att, y.nu, args.ref, args.vp)
    kp, kd = args.cp[GAINS.kp], args.cp[GAINS.kd]
    a = (-kp * e[0] - kd * ed[0], -kp * e[1] - kd * ed[1], -kp * e[2] - kd * ed[2])
    out.u[0], out.u[1], out.u[2] = input_for_accel_forces(y.att, args.vp, f, a, g)
    out.aux[0], out.aux[1], out.aux[2] = a
    return 0


def setup(params, ctx):
    """Pack the gains for ``control``; no internal state."""
    return CompiledController(cp=GAINS.pack(kp=params.kp, kd=params.kd), xc0=np.zeros(0), aux_names=AUX_NAMES)
