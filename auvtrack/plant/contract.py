"""The plant contract: what a plant module declares, and the compiled functions the engine calls.

A plant is one module (a built-in registered in :mod:`auvtrack.plant`, or a plug-in file selected
with ``plant.model = "plugin"`` and ``plant.module``) with

===============  ===================================================================================
``NAME``         its ``plant.model``
``STATE``        names of its state components, in order (``NX = len(STATE)``)
``COMMAND``      names of its actuator-command components (``N_CMD``)
``LOG_NAMES``    names of the extra channels it logs (``N_LOG``)
``ACCEPTS``      what a controller may command: ``("tau",)`` or ``("tau", "actuators")``
``Section``      pydantic model of its ``[plant]`` section (``model: Literal[NAME]``)
``setup``        ``setup(section, ctx) -> CompiledPlant``: packed parameters, initial state, record
compiled         the functions below (``njit_noalloc``: no allocation, arrays indexed, not sliced)
===============  ===================================================================================

:func:`~auvtrack.plant.registry.check_plant` checks all of this at registration and for a
plug-in, naming the file and the missing or wrong piece.  The stubs below document the compiled
functions; the engine's loop template (:mod:`auvtrack.engine.loop`) calls them through the name
``plant``, which each generated kernel binds to the plant's own module.

The float settings ``sf`` the engine hands to :func:`attitude_cause` follow :data:`SF`.
"""
from __future__ import annotations

from ..packing import packed_layout

SF = packed_layout("FloatSettings", dt=1, theta_lim=1, state_lim=1, win_t0=1, win_t1=1, phi_lim=1)
"""Engine float settings: RK4 step (s), |pitch| and |roll| limits (rad), state limit, metrics window (s)."""
CAUSE_PITCH = 2
CAUSE_ROLL = 5
SCRATCH_SIZE = 16  # length of the scratch array ``scr`` kept between a plant's rhs calls

NX = N_CMD = N_LOG = 0  # a plant module's own (len(STATE), len(COMMAND), len(LOG_NAMES))


def with_sizes(module):
    """``module`` with ``NX``, ``N_CMD`` and ``N_LOG`` set from its names when it does not define them.

    Parameters
    ----------
    module : module
        A plant module.

    Returns
    -------
    module
        The same module (the loop reads its sizes as constants).
    """
    for attr, names in (("NX", "STATE"), ("N_CMD", "COMMAND"), ("N_LOG", "LOG_NAMES")):
        if not hasattr(module, attr) and hasattr(module, names):
            setattr(module, attr, len(getattr(module, names)))
    return module


def pose(x):
    """(eta, nu): the 5-DOF projection of the state that controllers see.

    ``eta`` = (x, y, z, theta, psi) (m, rad), ``nu`` = (u, v, w, q, r) (m/s, rad/s), as 5-tuples.
    """
    raise NotImplementedError


def accel5(dx):
    """(u_dot, v_dot, w_dot, q_dot, r_dot) of a state derivative (for the lumped disturbance chi)."""
    raise NotImplementedError


def allocate(tau3, eta, nu, x, pp, prev, h, cmd):
    """Write the actuator command ``cmd`` for the controller's 3-vector ``tau3`` at the measured state.

    ``prev`` is the command in force (in continuous mode ``prev`` and ``cmd`` are the same array:
    read it before writing), ``h`` the sampling period (0 in continuous mode).  Returns a bitmask
    of the axes whose command could not be produced (the ``t_sat_tau_*`` metrics).
    """
    raise NotImplementedError


def rhs(t, x, att, cmd, env, pp, scr, fresh, dx):
    """Write dx = f(t, x, cmd).

    ``att`` is the attitude of x, ``env`` = (disturbance rows, current table), ``scr`` a scratch
    array kept between calls, ``fresh`` false when t and a state-free disturbance are unchanged
    since the last call.
    """
    raise NotImplementedError


def applied(x, cmd, pp):
    """(tau_u, tau_q, tau_r) the actuators produce now (logged, and used by the metrics)."""
    raise NotImplementedError


def feedback(x, cmd, pp):
    """(lo, hi, applied) for the controller, each a 3-tuple in the units it commands.

    ``lo`` and ``hi`` bound what each axis's actuators can produce now (tau at the current speed,
    or the actuators' own limits for a controller that commands them), ``applied`` is what they
    produce now (:class:`~auvtrack.control.contract.LawArgs`).
    """
    raise NotImplementedError


def effort(x, cmd, pp):
    """(f_u, f_q, f_r): each axis's actuator position now as a fraction of its limit (0 without a limit).

    The actuator-use metrics (``act_*``, ``t_act_limit_*``) accumulate it; 1 means at the limit.
    """
    raise NotImplementedError


def attitude_cause(x, sf):
    """A plant-specific stop (:data:`CAUSE_PITCH`, :data:`CAUSE_ROLL`) or 0, from the limits in ``sf``."""
    raise NotImplementedError


def log_extra(x, cmd, pp, log, row, col):
    """Write the plant's extra channels into ``log[row, col:col + N_LOG]``."""
    raise NotImplementedError


def example_arguments(x0, pp, n_cmd: int) -> dict:
    """Arguments of each compiled function with the types the engine's loop passes (to compile one alone).

    Parameters
    ----------
    x0 : numpy.ndarray
        A state (float64, C-contiguous; its length is the plant's ``NX``).
    pp : numpy.ndarray
        The packed parameters (float64, 1-D).
    n_cmd : int
        ``N_CMD``: the length of the actuator command.

    Returns
    -------
    dict
        Function name -> tuple of arguments (zeros, of the loop's types: 5- and 3-tuples of float,
        float64 arrays, an int64 row and column, a bool ``fresh``).
    """
    import numpy as np

    x, dx, cmd = np.zeros_like(x0), np.zeros_like(x0), np.zeros(n_cmd)
    f3, f5, att = (0.0,) * 3, (0.0,) * 5, (1.0, 0.0, 1.0, 0.0)
    env = (np.zeros((1, 1)), np.zeros((1, 1)))
    xcp = (x, cmd, pp)
    return {"pose": (x,), "accel5": (dx,), "allocate": (f3, f5, f5, x, pp, cmd, 0.0, cmd),
            "rhs": (0.0, x, att, cmd, env, pp, np.zeros(SCRATCH_SIZE), True, dx), "applied": xcp,
            "feedback": xcp, "effort": xcp, "attitude_cause": (x, np.zeros(SF.size)),
            "log_extra": (*xcp, np.zeros((1, 1)), 0, 0)}
