"""The actuators' reach of a 6-DOF truth at a cruise speed: what its fins and propeller can produce.

At straight, level running at surge speed U0 (v = w = p = q = r = 0, actuators at rest), the
plant's own ``feedback`` (:func:`auvtrack.plant.sixdof.feedback`: the tau of the propeller at
-+n_max and of the stern planes and rudder at -+delta_max, through the model's force equations
:func:`~auvtrack.plant.sixdof.prestero.produced` / :func:`~auvtrack.plant.sixdof.fossen.produced`)
gives per axis the least and greatest tau; the reach is the smaller magnitude of the two
(N, N m, N m).  For Prestero's model the fin moments are M_uu_ds U0^2 delta_max and
N_uu_dr U0^2 delta_max and the thrust X_prop (n_max/n0)^2 (P01 ch. 4; the numbers with their
sources in ``auvtrack/data/vehicles/6dof/remus100_prestero.toml``); for a Fossen-type file the
fins' lift and the propeller's thrust at the advance speed (F21 Section 8.4.2; the vehicle file's
numbers).  Registered with :func:`auvtrack.vehicle.presets.register_reach`, so that a
reduced design preset (``remus100``, a vehicle file) carries the reach of the truth it comes from.
"""
from __future__ import annotations

import functools

import numpy as np


@functools.lru_cache(maxsize=256)
def reach_at(model: str, u0: float) -> tuple[tuple[float, float, float], str] | None:
    """The reach of a 6-DOF truth at surge speed ``u0``.

    Parameters
    ----------
    model : str
        A 6-DOF truth name (``remus100_prestero``, ``remus100_fossen``, a shipped Fossen-type
        file) or a vehicle file's path.
    u0 : float
        Surge speed, m/s.

    Returns
    -------
    tuple or None
        ((tau_u (N), tau_q (N m), tau_r (N m)), source text); None for a name that is not a truth.
    """
    from . import feedback
    from .layout import P_DMAX, P_NMAX
    from .truth import initial_state, pack_truth

    try:
        pp = pack_truth(model)
    except KeyError:
        return None
    x = initial_state(nu6=(float(u0), 0.0, 0.0, 0.0, 0.0, 0.0))
    lo, hi, _ = feedback(x, np.zeros(6), pp)
    reach = tuple(float(min(abs(a), abs(b))) for a, b in zip(lo, hi))
    source = (f"tau of {model}'s actuators at their limits (delta_max = {pp[P_DMAX]:.6g} rad, n_max = "
              f"{pp[P_NMAX]:.6g} rpm) in straight running at U0 = {u0:.6g} m/s, the smaller magnitude of the two "
              f"limits per axis (auvtrack/plant/sixdof/reach.py)")
    return reach, source
