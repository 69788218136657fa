"""The 5-DOF ``remus100`` preset as a reduction of the 6-DOF ``remus100_prestero`` data at a speed U0.

One source of truth: the numbers come from ``auvtrack/data/vehicles/6dof/remus100_prestero.toml``;
the reduction (docs/vehicles.md, section ``remus100``) is::

    m11 = m - X_udot,  m22 = m - Y_vdot,  m33 = m - Z_wdot,  m44 = I_yy - M_qdot,  m55 = I_zz - N_rdot
    d11 = -2 X_u|u| U0,  d22 = -Y_uv U0,  d33 = -Z_uw U0,  d44 = -M_uq U0,  d55 = -N_ur U0
    rho g nabla GM_L = W z_g          (neutral buoyancy assumed: P01's B - W = 7 N is dropped)

i.e. roll, the off-diagonal added mass, the cross-flow drag (zero slope at rest) and the Munk /
lift moments M_uw, N_uv are dropped, and the quadratic drag and the u-proportional lift are
linearised about straight running at U0 (Fossen 2021, Section 7.x: linearisation about a cruise
speed).  The lift damping therefore scales with U0: the scenario loader uses the mean speed of
the scenario's reference by default (:func:`reference_speed`), ``vehicle.u0`` overrides it.
"""
from __future__ import annotations

import functools
import math
from types import MappingProxyType
from typing import Mapping

import numpy as np

from .truth_presets import load_preset6

SOURCE_6DOF = "remus100_prestero"
U0_MIN, U0_MAX = 0.05, 3.0  # m/s: the range a linearisation speed may take


@functools.lru_cache(maxsize=None)
def _values6(name: str) -> Mapping[str, float | tuple]:
    """The checked numbers of a 6-DOF preset, read once (read-only: every run of a batch reduces them)."""
    return MappingProxyType(dict(load_preset6(name).values))


def reduce_prestero(u0: float) -> dict:
    """The 5-DOF numbers of the REMUS 100 linearised at U0.

    Parameters
    ----------
    u0 : float
        Linearisation (cruise) speed, m/s, in [:data:`U0_MIN`, :data:`U0_MAX`].

    Returns
    -------
    dict
        ``m`` (5), ``d`` (5), ``wgml`` and ``sources`` (per field: unit and source text).

    Raises
    ------
    ValueError
        ``vehicle.u0`` out of range.
    """
    if not (isinstance(u0, (int, float)) and U0_MIN <= u0 <= U0_MAX):
        raise ValueError(f"vehicle.u0: must be a speed in [{U0_MIN}, {U0_MAX}] m/s (got {u0!r})")
    v = _values6(SOURCE_6DOF)
    m = v["mass.W"] / v["mass.g"]
    mm = (m - v["added_mass.X_udot"], m - v["added_mass.Y_vdot"], m - v["added_mass.Z_wdot"],
          v["mass.Iyy"] - v["added_mass.M_qdot"], v["mass.Izz"] - v["added_mass.N_rdot"])
    d = (-2.0 * v["drag.X_uu"] * u0, -v["combined.Y_uv"] * u0, -v["combined.Z_uw"] * u0,
         -v["combined.M_uq"] * u0, -v["combined.N_ur"] * u0)
    wgml = v["mass.W"] * v["mass.r_g"][2]
    src = f"reduction of {SOURCE_6DOF} (P01 data, auvtrack/vehicle/reduction.py)"
    return {
        "m": tuple(float(x) for x in mm), "d": tuple(float(x) for x in d), "wgml": float(wgml),
        "sources": {
            "m": {"unit": "kg, kg, kg, kg m^2, kg m^2",
                  "source": f"{src}: m - X_udot, m - Y_vdot, m - Z_wdot, I_yy - M_qdot, I_zz - N_rdot; off-diagonal added mass dropped (assumed)"},
            "d": {"unit": "N s/m (surge, sway, heave); N m s/rad (pitch, yaw)",
                  "source": f"{src}: -2 X_u|u| U0, -Y_uv U0, -Z_uw U0, -M_uq U0, -N_ur U0 at U0 = {u0:.6g} m/s"},
            "wgml": {"unit": "N m", "source": f"{src}: W z_g, neutral buoyancy assumed (P01 has B - W = 7 N)"},
        },
    }


def reference_speed(reference, duration: float, n: int = 2001) -> float:
    """Mean speed |d eta_d / dt| of a reference over [0, duration] (m/s), on n equally spaced times.

    Parameters
    ----------
    reference : auvtrack.reference.Reference
        The reference.
    duration : float
        Time span, s (a finite path's own duration caps it).
    n : int
        Number of sample times.

    Returns
    -------
    float
        The mean speed (trapezoidal rule).
    """
    T = min(float(duration), reference.duration)
    ts = np.linspace(0.0, T, n)
    _, vel, _ = reference.evaluate(ts)
    s = np.linalg.norm(vel, axis=1)
    return float(np.trapezoid(s, ts) / T) if T > 0 else float(s[0])


def default_u0(reference, duration: float) -> float:
    """U0 for a scenario: its reference's mean speed, refused outside the linearisation range.

    Raises
    ------
    ValueError
        ``vehicle.u0: ...`` when the reference is (nearly) stationary or too fast.
    """
    u = reference_speed(reference, duration)
    if not (U0_MIN <= u <= U0_MAX) or not math.isfinite(u):
        raise ValueError(f"vehicle.u0: the reference's mean speed {u:.3g} m/s is outside [{U0_MIN}, {U0_MAX}] m/s; "
                         "give vehicle.u0 explicitly")
    return u
