"""The controller contract: what a controller module declares, and what its compiled law receives.

A controller is one module (a built-in in :mod:`auvtrack.control`, or a plug-in file) with

=================  =================================================================================
``NAME``           its ``controller.kind``
``AUX_NAMES``      names of the channels it logs (unique, not a built-in channel's name)
``Params``         pydantic model of its ``[controller]`` section (``kind: Literal[NAME]``); a gain
                   field may declare its search space for tuning (:func:`tunable`)
``setup``          ``setup(params, ctx) -> CompiledController``: packs its gains and initial state
                   from its own section ``params`` and the :class:`~auvtrack.control.registry.SetupContext`
                   ``ctx``; refuses gains that break its conditions with a one-line ``ValueError``
``control``        the compiled law (below)
``COMMANDS``       optional, ``"tau"`` (default: generalised forces [tau_u, tau_q, tau_r]),
                   ``"actuators"`` (one actuator command per axis, e.g. propeller rpm, stern plane,
                   rudder on a 6-DOF plant) or both in order of preference (``ctx.commands`` says
                   which one a run uses)
``TRACKS``         optional, ``True`` (default) when it tracks the reference (open-loop inputs: False)
``PLANTS``         optional, the plant models it runs on (default: every plant that accepts its commands)
``SECTIONS``       optional, other scenario sections it reads (e.g. ``("envelope", "estimator")``)
``STATUS``         optional, ``{code: message}`` of its own failure codes (>= 10)
``warnings``       optional, ``warnings(params) -> list[str]`` shown by ``auvtrack check``
=================  =================================================================================

:func:`~auvtrack.control.registry.check_controller` checks all of this when a controller is
registered or a plug-in is loaded, and names the file and the missing or wrong piece.

The compiled law
----------------
::

    control(t, y, xc, args, out) -> int status

=======  ==============================================================================
t        time (s)
y        :class:`Measured`: what the vehicle's sensors give
xc       the controller's own state (its ``xc0`` evolved), read only
args     :class:`LawArgs`: the reference, the gains, the nominal model, what the actuators can do
out      :class:`LawOutputs`: where the law writes its command, its state derivative and its channels
status   0 = ok, otherwise a code of :data:`CONTROLLER_STATUS` or of the controller's ``STATUS``
=======  ==============================================================================

The engine calls the law at every RK4 stage (continuous mode) or once per control sample
(sampled-data mode, its command and state derivative then held).  Arrays are passed whole and
indexed: slicing in the hot path creates reference-counted views that cost more than the
arithmetic.
"""
from __future__ import annotations

from typing import NamedTuple

import numpy as np

WORK_SIZE = 512  # length of the scratch array the engine hands to a controller

CONTROLLER_STATUS = {
    1: "envelope violated: |e_i| >= rho_i (the error transformation is undefined)",
    2: "start on or outside the envelope and widen_start is off",
    3: "controller produced a non-finite input",
}
"""Status codes shared by every controller (1-9 are reserved for these)."""

COMMAND_KINDS = ("tau", "actuators")
"""What a controller can command: generalised forces, or the actuators themselves."""


class Measured(NamedTuple):
    """What the law measures (with sensor noise in sampled-data mode).

    Attributes
    ----------
    eta : tuple of 5 float
        (x, y, z, theta, psi): position (m, NED) and attitude (rad); with a 6-DOF plant the
        projection of its state (roll is neither measured nor controlled).
    nu : tuple of 5 float
        (u, v, w, q, r): body velocities (m/s) and rates (rad/s).
    att : tuple of 4 float
        (cos theta, sin theta, cos psi, sin psi) of ``eta``, computed once by the engine.
    """

    eta: tuple
    nu: tuple
    att: tuple


class LawArgs(NamedTuple):
    """Everything else the law reads.

    Attributes
    ----------
    ref : numpy.ndarray
        (3, 3): rows eta_d, eta_d_dot, eta_d_ddot of the virtual point's reference at ``t``.
    path : numpy.ndarray
        The packed reference itself: ``auvtrack.reference.eval_reference(path, s, rows)`` gives
        its rows at any time ``s`` (a preview, a path parameter).
    cp : numpy.ndarray
        The controller's packed parameters (its own layout).
    vp : numpy.ndarray
        The packed *nominal* 5-DOF vehicle (:mod:`auvtrack.vehicle.params`); the law never sees
        the true plant.
    lo, hi : tuple of 3 float
        The least and greatest command each axis's actuators can produce now, in the law's command
        units (tau: N, N m, N m at the current speed; actuators: their limits); +-inf when unlimited.
    applied : tuple of 3 float
        What the actuators produce now, in the same units (it differs from the command when they
        saturate, lag or are rate limited).
    h : float
        Control period (s); 0 in continuous mode.
    work : numpy.ndarray
        Scratch (float64, length :data:`WORK_SIZE`) for variable-size temporaries.
    """

    ref: np.ndarray
    path: np.ndarray
    cp: np.ndarray
    vp: np.ndarray
    lo: tuple
    hi: tuple
    applied: tuple
    h: float
    work: np.ndarray


class LawOutputs(NamedTuple):
    """Where the law writes.

    Attributes
    ----------
    u : numpy.ndarray
        (3,): the command: tau = [tau_u (N), tau_q (N m), tau_r (N m)], or one actuator command
        per axis for a controller with ``COMMANDS = "actuators"``.
    dxc : numpy.ndarray
        d/dt of ``xc``.
    aux : numpy.ndarray
        The logged channels ``AUX_NAMES``.
    """

    u: np.ndarray
    dxc: np.ndarray
    aux: np.ndarray


def control(t: float, y: Measured, xc: np.ndarray, args: LawArgs, out: LawOutputs) -> int:
    """The compiled law of a controller module (this stub stands for it in the engine's loop template).

    Parameters
    ----------
    t : float
        Time (s).
    y : Measured
        The measured state.
    xc : numpy.ndarray
        The controller's own state (read only).
    args : LawArgs
        Reference, gains, nominal model and what the actuators can do.
    out : LawOutputs
        Written: the command, d/dt of ``xc``, the logged channels.

    Returns
    -------
    int
        0, or a failure code (:data:`CONTROLLER_STATUS`, the controller's ``STATUS``).
    """
    raise NotImplementedError("the engine binds each kernel to a controller's own law")


UNLIMITED = ((-np.inf, -np.inf, -np.inf), (np.inf, np.inf, np.inf))
"""(lo, hi) of actuators without limits."""


def evaluate(law, t: float, eta, nu, xc, ref, cp, vp, *, n_aux: int, path=None, lo=UNLIMITED[0],
             hi=UNLIMITED[1], applied=(0.0, 0.0, 0.0), h: float = 0.0) -> tuple[int, np.ndarray, np.ndarray, np.ndarray]:
    """Call a compiled law once, outside the engine (tests, a plug-in's first check, a policy's observation).

    Parameters
    ----------
    law : callable
        A controller module's compiled ``control``.
    t : float
        Time (s).
    eta, nu : sequence of 5 float
        The measured state; its attitude is computed here.
    xc : array_like
        The controller's state.
    ref : array_like
        (3, 3) reference rows at ``t``.
    cp, vp : array_like
        Packed gains and nominal vehicle.
    n_aux : int
        Number of logged channels.
    path : array_like, optional
        The packed reference (default: empty).
    lo, hi, applied : sequence of 3 float, optional
        Actuator feedback (default: unlimited, nothing applied).
    h : float, optional
        Control period (s).

    Returns
    -------
    (int, numpy.ndarray, numpy.ndarray, numpy.ndarray)
        Status, command u, d/dt of xc, and the logged channels.
    """
    from ..vehicle.kinematics import attitude

    eta = tuple(float(v) for v in eta)
    nu = tuple(float(v) for v in nu)
    xc = np.ascontiguousarray(xc, dtype=np.float64).copy()
    u, dxc, aux = np.zeros(3), np.zeros(xc.size), np.zeros(max(n_aux, 0))
    args = LawArgs(np.ascontiguousarray(ref, dtype=np.float64), np.ascontiguousarray(
        np.zeros(0) if path is None else path, dtype=np.float64), np.ascontiguousarray(cp, dtype=np.float64),
        np.ascontiguousarray(vp, dtype=np.float64), tuple(float(v) for v in lo), tuple(float(v) for v in hi),
        tuple(float(v) for v in applied), float(h), np.zeros(WORK_SIZE))
    status = law(float(t), Measured(eta, nu, attitude(eta[3], eta[4])), xc, args, LawOutputs(u, dxc, aux))
    return status, u, dxc, aux
