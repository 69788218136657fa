"""PID baseline: computed torque through the nominal model with a PID outer loop on e.

Per axis i of the virtual-point error e (docs/controllers.md, eq. P1-P3):

    a_i     = -kp e_i - kd e_dot_i - ki I_i                          (P1, m/s^2)
    I_dot_i = e_i - (kaw / ki) da_i                                  (P2, back-calculation)
    tau     = input_for_accel(a)                                     (eq. 4 inverted, tracking.py)

The input map makes e_ddot = a on the nominal model, and e_ddot contains -eta_d_ddot (eq. 15):
the reference acceleration is fed forward.  On the disturbance-free nominal plant the error
obeys the linear law e''' + kd e'' + kp e' + ki e = 0 (P3), Hurwitz iff kp, kd > 0, 0 <= ki <
kd kp (Routh-Hurwitz; checked in :func:`setup`).  da is the e_ddot that the actuators' reach
[lo, hi] (``args.lo``, ``args.hi``: what each axis can produce now, from the plant) removes on the
nominal model, da = J3 M_bar^-1 (sat(tau) - tau) (u, q, r rows, :mod:`auvtrack.control.saturation`);
feeding it back stops the integrator from winding up (0 without saturation).  ``saturation =
"compensated"`` (the default) is (P2); ``"published"`` is the textbook PID without anti-windup,
I_dot = e.

Sources: computed-torque (inverse-dynamics) control with a PD/PID outer loop and reference
acceleration feed-forward, Spong, Hutchinson & Vidyasagar (2006), *Robot Modeling and Control*,
ch. 8 (inverse dynamics); back-calculation anti-windup with tracking gain 1/T_t, Astrom &
Hagglund (2006), *Advanced PID Control*, ch. 3 (integrator windup).

Packed gains :data:`GAINS` (``kaw_ki`` = kaw / ki, 0 if ki = 0; ``saturation`` its code); internal
state xc = I (3, m s); logged aux: I_x, I_y, I_z.
"""
from __future__ import annotations

import numpy as np
from pydantic import Field
from typing import Literal

from ..jit import njit, njit_noalloc
from ..packing import packed_layout
from .gain_checks import require
from .registry import CompiledController, ControllerParams, tunable
from .saturation import COMPENSATED, SATURATION, accel_deficit, code
from .tracking import error_state_forces, input_for_accel_forces

NAME = "pid"
AUX_NAMES = ("I_x", "I_y", "I_z")
TIME_EXPONENTS = {"kp": 2, "ki": 3, "kd": 1, "kaw": 1}
"""Gain -> its time dimension n (units s^-n): the gain design scales g by omega^n (control/design.py, D1)."""
GAINS = packed_layout("PIDGains", kp=1, ki=1, kd=1, kaw_ki=1, saturation=1)


class Params(ControllerParams):
    """Computed-torque PID on the virtual-point error (docs/controllers.md, eq. P1-P3).

    The defaults place the three poles of eq. (P3) at s = -1 rad/s: (s + 1)^3.
    """

    kind: Literal["pid"] = "pid"
    kp: float = tunable(3.0, 0.01, 30.0, log=True, gt=0, description="proportional gain, 1/s^2")
    ki: float = tunable(1.0, 1e-5, 30.0, log=True, ge=0, description="integral gain, 1/s^3 (0: PD); ki < kd kp")
    kd: float = tunable(3.0, 0.05, 30.0, log=True, gt=0, description="derivative gain, 1/s")
    kaw: float = tunable(1.0, 0.01, 10.0, log=True, ge=0, description="back-calculation (anti-windup) gain 1/T_t, 1/s")
    saturation: Literal[SATURATION] = Field(
        "compensated", description="'compensated': back-calculation from the actuators' reach (eq. P2); "
        "'published': the textbook PID, I_dot = e")


@njit
def axis(e, ed, i, kp, ki, kd):
    """a = -kp e - kd e_dot - ki I of one axis, eq. (P1) (m/s^2)."""
    return -kp * e - kd * ed - ki * i


@njit_noalloc(inline="always")
def control(t, y, xc, args, out):
    """Compiled PID law, eq. (P1)-(P2) (tau in N, N m; the reach from ``args.lo``, ``args.hi``); returns 0."""
    att, vp, cp, tau, dxc = y.att, args.vp, args.cp, out.u, out.dxc
    e, ed, f, gf = error_state_forces(y.eta, att, y.nu, args.ref, vp)
    kp, ki, kd = cp[GAINS.kp], cp[GAINS.ki], cp[GAINS.kd]
    a = (axis(e[0], ed[0], xc[0], kp, ki, kd), axis(e[1], ed[1], xc[1], kp, ki, kd),
         axis(e[2], ed[2], xc[2], kp, ki, kd))
    t0, t1, t2 = input_for_accel_forces(att, vp, f, a, gf)
    tau[0], tau[1], tau[2] = t0, t1, t2
    on = 1.0 if ki > 0.0 else 0.0  # a PD keeps its (unused) integrator at rest
    if cp[GAINS.saturation] == COMPENSATED:
        # e_ddot the actuators' reach removes on the nominal model: J3 M_bar^-1 (sat(tau) - tau)
        da = accel_deficit(att, vp, (t0, t1, t2), args.lo, args.hi)[0]
        g = cp[GAINS.kaw_ki]
        dxc[0] = on * (e[0] - g * da[0])
        dxc[1] = on * (e[1] - g * da[1])
        dxc[2] = on * (e[2] - g * da[2])
    else:
        dxc[0], dxc[1], dxc[2] = on * e[0], on * e[1], on * e[2]
    out.aux[0], out.aux[1], out.aux[2] = xc[0], xc[1], xc[2]
    return 0


def check(p: Params) -> None:
    """Routh-Hurwitz condition of eq. (P3): s^3 + kd s^2 + kp s + ki is Hurwitz iff ki < kd kp.

    Parameters
    ----------
    p : Params
        The gains (their signs are already checked by the model).

    Raises
    ------
    ValueError
        ``controller.ki: ...`` when ki >= kd kp.
    """
    require(p.ki < p.kd * p.kp, "ki",
            f"must be < kd * kp = {p.kd * p.kp:.6g} (Routh-Hurwitz: e''' + kd e'' + kp e' + ki e = 0 stable)",
            p.ki)


def setup(params: Params, ctx) -> CompiledController:
    """Check eq. (P3)'s stability condition and pack the gains; I(0) = 0."""
    p = params
    check(p)
    cp = GAINS.pack(kp=p.kp, ki=p.ki, kd=p.kd, kaw_ki=p.kaw / p.ki if p.ki > 0 else 0.0,
                    saturation=code(p.saturation))
    notes = ()
    if p.ki > 0 and (p.kaw == 0 or p.saturation == "published"):
        notes = ("pid: no back-calculation (controller.kaw = 0 or saturation = \"published\"): the integrator "
                 "winds up while the actuators saturate",)
    poles = np.roots([1.0, p.kd, p.kp, p.ki] if p.ki > 0 else [1.0, p.kd, p.kp])  # of eq. (P3)
    return CompiledController(cp=cp, xc0=np.zeros(3), aux_names=AUX_NAMES, notes=notes,
                              resolved={"error_poles": [[float(z.real), float(z.imag)] for z in poles]})


def nominal_axis(p: Params, axis_index: int, e0: float):
    """One axis of the nominal closed loop e_ddot = a (P1) from e(0) = e0 at rest, for the gain design's peak demand.

    Parameters
    ----------
    p : Params
        The gains.
    axis_index : int
        0, 1, 2 (x, y, z; the PID's gains are shared by the axes).
    e0 : float
        Initial error, m.

    Returns
    -------
    (callable, list)
        ``f(t, x) -> (x_dot, a)`` over x = (e, e_dot, integral of e), and x(0).
    """
    def f(t, x):
        a = axis(x[0], x[1], x[2], p.kp, p.ki, p.kd)
        return np.array([x[1], a, x[0] if p.ki > 0 else 0.0]), a
    return f, [e0, 0.0, 0.0]
