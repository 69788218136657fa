"""The 6-DOF truth models by preset: packing the parameters, and a Python-side reference integrator.

``MODELS`` maps a preset name to its model module (:mod:`auvtrack.plant.sixdof.prestero`,
:mod:`auvtrack.plant.sixdof.fossen`); each provides ``pack(preset, common)``, the compiled
``derivative(x, att, vc, dist, cmd, pp, dx)``, ``produced`` and ``allocate_tau``.
:func:`pack_truth` builds the packed parameters with the actuator block filled from the preset
(optionally overridden, e.g. by ``plant.delta_rate_max``).
"""
from __future__ import annotations

import math
from types import ModuleType

import numpy as np

from . import fossen, prestero
from ...vehicle.kinematics import attitude
from .layout import (EQUATIONS_FOSSEN, EQUATIONS_PRESTERO, IX_DR, IX_DS, IX_N, NX6, P_DIRECT, P_EQUATIONS, P_DMAX, P_DRATE, P_MINV, P_NMAX, P_NRATE,
                      P_TDELTA, P_TN, PP6_SIZE)
from ...vehicle.truth_presets import Preset6, available6, load_preset6
from ...vehicle.vehicle_file import is_vehicle_ref, load_vehicle_file, shipped_dir

MODELS: dict[str, ModuleType] = {"remus100_prestero": prestero, "remus100_fossen": fossen}
EQUATIONS = {prestero: EQUATIONS_PRESTERO, fossen: EQUATIONS_FOSSEN}
"""The code of each model's equations of motion in ``pp[P_EQUATIONS]``."""


def truth_preset(name: str) -> tuple[Preset6, ModuleType]:
    """The numbers and the model module of a 6-DOF truth.

    Parameters
    ----------
    name : str
        A key of :data:`MODELS`, the name of another shipped 6-DOF file (a Fossen-type vehicle
        file, e.g. ``remus600``) or the path of a vehicle file (``.toml``, relative to the
        working directory).

    Returns
    -------
    (Preset6, module)
        The checked numbers, and :mod:`~auvtrack.plant.sixdof.prestero` or
        :mod:`~auvtrack.plant.sixdof.fossen` (every vehicle file is a Fossen-type torpedo).

    Raises
    ------
    KeyError
        An unknown name.
    ValueError
        A vehicle file that breaks its rules (:mod:`auvtrack.plant.sixdof.vehicle_file`).
    """
    if name in MODELS:
        return load_preset6(name), MODELS[name]
    if is_vehicle_ref(name):
        return load_vehicle_file(name), fossen
    if name in available6():
        return load_vehicle_file(shipped_dir() / f"{name}.toml"), fossen
    raise KeyError(f"unknown 6-DOF preset {name!r}; choose one of {available6()} or a vehicle file (.toml)")


def model_of(name: str) -> ModuleType:
    """The model module (:mod:`~auvtrack.plant.sixdof.prestero` or :mod:`~auvtrack.plant.sixdof.fossen`) of a truth ``name``."""
    return MODELS.get(name) or truth_preset(name)[1]

ACTUATOR_KEYS = ("delta_max", "n_max", "T_delta", "T_n", "delta_rate_max", "n_rate_max")
_SLOTS = dict(zip(ACTUATOR_KEYS, (P_DMAX, P_NMAX, P_TDELTA, P_TN, P_DRATE, P_NRATE)))
_RANGES = {"delta_max": (0.0, math.pi / 2, "rad, in (0, pi/2]"), "n_max": (0.0, math.inf, "rpm, > 0"),
           "T_delta": (0.0, math.inf, "s, > 0"), "T_n": (0.0, math.inf, "s, > 0"),
           "delta_rate_max": (0.0, math.inf, "rad/s, > 0 (inf = none)"),
           "n_rate_max": (0.0, math.inf, "rpm/s, > 0 (inf = none)")}


def actuator_values(pr: Preset6, overrides: dict | None = None) -> dict:
    """The actuator numbers of a preset with ``overrides`` applied, checked.

    Raises
    ------
    ValueError
        ``"plant.<key>: must be <range> (got <value>)"`` for a value out of range.
    """
    vals = {k: pr.values[f"actuators.{k}"] for k in ACTUATOR_KEYS}
    for k, x in (overrides or {}).items():
        if k not in vals:
            raise ValueError(f"plant.{k}: unknown actuator setting; allowed {list(ACTUATOR_KEYS)}")
        vals[k] = float(x)
    for k, x in vals.items():
        lo, hi, text = _RANGES[k]
        if not (x > lo and (x <= hi)) or math.isnan(x) or (k in ("delta_max", "n_max", "T_delta", "T_n") and math.isinf(x)):
            raise ValueError(f"plant.{k}: must be {text} (got {x})")
    return vals


def pack_truth(name: str, overrides: dict | None = None, direct: bool = False) -> np.ndarray:
    """Packed parameters ``pp`` of the 6-DOF preset ``name``.

    Parameters
    ----------
    name : str
        A truth (:func:`truth_preset`).
    overrides : dict, optional
        Actuator settings replacing the preset's (keys :data:`ACTUATOR_KEYS`).
    direct : bool
        The controller commands the actuators directly (``open_loop_actuators``).

    Returns
    -------
    numpy.ndarray
        Length :data:`auvtrack.plant.sixdof.layout.PP6_SIZE`.
    """
    pr, model = truth_preset(name)
    common = np.zeros(PP6_SIZE)
    for k, x in actuator_values(pr, overrides).items():
        common[_SLOTS[k]] = x
    common[P_DIRECT] = 1.0 if direct else 0.0
    common[P_EQUATIONS] = EQUATIONS[model]
    return model.pack(pr, common)


def trim_rpm(name: str, pp: np.ndarray, u: float) -> float:
    """Propeller speed (rpm) at which straight, level running at surge speed u is in surge balance.

    Solves X(u, n) = 0 for n by bisection on [0, n_max], X the surge component of the generalized
    force M nu_dot (fins at zero, everything else at rest but u); 0 for u <= 0.  Used to start a
    6-DOF run at speed with its propeller trimmed.

    Raises
    ------
    ValueError
        ``initial.nu: surge speed u needs more than n_max`` when u is out of the propeller's reach.
    """
    if u <= 0.0:
        return 0.0
    model = model_of(name)
    dx = np.zeros(NX6)
    cmd = np.zeros(6)
    att = attitude(0.0, 0.0)

    M = np.linalg.inv(pp[P_MINV:P_MINV + 36].reshape(6, 6))

    def accel(n):
        x = initial_state(nu6=(u, 0, 0, 0, 0, 0), actuators=(0.0, 0.0, n))
        cmd[2] = n
        model.derivative(x, att, (0.0, 0.0, 0.0), (0.0,) * 6, cmd, pp, dx)
        return float(M[0] @ dx[6:12])
    lo, hi = 0.0, float(pp[P_NMAX])
    if accel(hi) < 0.0:
        raise ValueError(f"initial.nu: surge speed u = {u:g} m/s needs more than the propeller's "
                         f"{hi:g} rpm (plant {name})")
    for _ in range(80):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if accel(mid) < 0.0 else (lo, mid)
    return 0.5 * (lo + hi)


def initial_state(eta6=(0.0,) * 6, nu6=(0.0,) * 6, actuators=(0.0, 0.0, 0.0)) -> np.ndarray:
    """x0 (length :data:`NX6`) from pose, velocity and actuator states (rad, rad, rpm)."""
    x = np.zeros(NX6)
    x[0:6], x[6:12] = eta6, nu6
    x[IX_DR], x[IX_DS], x[IX_N] = actuators
    return x


def integrate_open_loop(name: str, commands, t_end: float, dt: float, x0=None,
                        vc=(0.0, 0.0, 0.0), times=(), pp=None, dist=(0.0,) * 6) -> dict:
    """RK4 of the truth model under constant actuator commands (a reference for tests and checks).

    Parameters
    ----------
    name : str
        Preset.
    commands : sequence of 3 float
        (delta_r (rad), delta_s (rad), n (rpm)).
    t_end, dt : float
        Duration and step (s).
    x0 : array_like, optional
        Initial state (default: at rest, actuators at 0).
    vc : sequence of 3 float
        Constant NED current (m/s).
    times : sequence of float
        Times (multiples of dt) at which to return the state.
    pp : numpy.ndarray, optional
        Packed parameters (default: the preset's, :func:`pack_truth`).
    dist : sequence of 6 float
        Constant disturbance [X, Y, Z, K, M, N] (N, N m).

    Returns
    -------
    dict
        ``{t: state}`` for each requested time, and ``"final"``.
    """
    model = model_of(name)
    pp = pack_truth(name) if pp is None else pp
    x = initial_state() if x0 is None else np.array(x0, dtype=np.float64)
    cmd = np.zeros(6)
    cmd[0:3] = commands
    dist = tuple(float(d) for d in dist)
    vc = tuple(float(c) for c in vc)
    k1, k2, k3, k4, xs = (np.zeros(NX6) for _ in range(5))
    want = {int(round(t / dt)): t for t in times}
    out = {}
    nsteps = int(round(t_end / dt))
    def f(z, k):
        model.derivative(z, attitude(z[4], z[5]), vc, dist, cmd, pp, k)
    for i in range(nsteps):
        f(x, k1)
        np.add(x, 0.5 * dt * k1, out=xs)
        f(xs, k2)
        np.add(x, 0.5 * dt * k2, out=xs)
        f(xs, k3)
        np.add(x, dt * k3, out=xs)
        f(xs, k4)
        x += dt / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4)
        if i + 1 in want:
            out[want[i + 1]] = x.copy()
    out["final"] = x.copy()
    return out
