"""The paper's 5-DOF design model of a Fossen-type torpedo, linearised about straight running at U0.

The method of :mod:`auvtrack.vehicle.reduction` (Prestero's REMUS) and of Prestero (2001, ch. 9):
keep u, v, w, q, r; take the diagonal of the mass matrix; linearise each hydrodynamic force about
straight, level running at u = U0 (v = w = p = q = r = 0, fins at zero, theta = phi = 0) and keep
the slope of each force in its own velocity; the pitch restoring moment's slope in theta.  For
the model of :mod:`auvtrack.plant.sixdof.fossen` (F21 Section 8.4.2; numbers from
:func:`~auvtrack.plant.sixdof.fossen.derived`)::

    m11 = M[0,0] = m + m_f k1          m22 = M[1,1] = m + m_f k2        m33 = M[2,2] = m + m_f k2
    m44 = M[4,4] = Iy + m z_g^2 + k' Iy_f                                m55 = M[5,5] = Iz + m z_g^2 + k' Iy_f
    d11 = -dX/du = D11 e^{-3 U0} (1 - 3 U0) + rho S CD_0 U0   (fading linear damping, hull drag 1/2 rho S CD_0 u^2)
    d22 = -dY/dv = D22 e^{-3 U0}                              (cross-flow drag has zero slope at v = 0)
    d33 = -dZ/dw = D33 + 1/2 rho S U0 (CL_alpha + CD_0)       (hull lift and drag at alpha = w/U0)
    d44 = -dM/dq = D55 = 2 zeta_pitch w_pitch M55
    d55 = -dN/dr = D66 = M66 / T_yaw                          (cross-flow drag has zero slope at r = 0)
    rho g nabla GM_L = W z_g - B z_b                          (Prestero 2001 eq. 9.7)

with M = M_RB + M_A about the CO, D the low-speed damping of the model and S, CD_0, CL_alpha the
hull-as-wing numbers.  The propeller's dependence on the speed is not damping of the design
model: the allocation produces the commanded tau_u at the measured speed.

What the 5-DOF structure cannot carry (dropped, as in :mod:`auvtrack.vehicle.reduction`): roll and
its couplings; the off-diagonal mass terms m z_g (surge-pitch, sway-roll); and the cross terms of
eq. 1's C0(nu), which are fixed by the diagonal masses: C0 puts (m11 - m33) U0 w in pitch and
(m22 - m11) U0 v in yaw (the Munk moments), where Fossen's model has none (it zeroes those
added-mass Coriolis entries), and m11 U0 r, m11 U0 q in sway and heave where the model has the
rigid-body m U0 r, m U0 q.  ``tests/vehicle/test_vehicle_file.py`` measures both against the truth's
finite-difference linearisation.
"""
from __future__ import annotations

import math

from ...vehicle.presets import PresetSource, VehiclePreset
from ...vehicle.reduction import U0_MAX, U0_MIN
from ...vehicle.truth_presets import Preset6
from . import fossen


def reduce_torpedo(pr: Preset6, u0: float, origin: str = "") -> dict:
    """The 5-DOF numbers of a Fossen-type torpedo linearised at U0 (module docstring).

    Parameters
    ----------
    pr : Preset6
        A Fossen-type vehicle (``remus100_fossen`` or a vehicle file).
    u0 : float
        Linearisation (cruise) speed, m/s, in [:data:`~auvtrack.vehicle.reduction.U0_MIN`,
        :data:`~auvtrack.vehicle.reduction.U0_MAX`].
    origin : str
        Name of the file, for the sources.

    Returns
    -------
    dict
        ``m`` (5), ``d`` (5), ``wgml`` and ``sources`` (per field: unit and source text), as
        :func:`auvtrack.vehicle.reduction.reduce_prestero`.

    Raises
    ------
    ValueError
        ``vehicle.u0`` out of range, or a linearisation with negative damping.
    """
    if not (isinstance(u0, (int, float)) and U0_MIN <= u0 <= U0_MAX):
        raise ValueError(f"vehicle.u0: must be a speed in [{U0_MIN}, {U0_MAX}] m/s (got {u0!r})")
    dd = fossen.derived(pr)
    M, D = dd["M"], dd["D"]
    rho, S, cd0, cla = pr.values["hull.rho"], dd["S"], dd["CD_0"], dd["CL_alpha"]
    fade = math.exp(-3.0 * u0)
    m = (M[0, 0], M[1, 1], M[2, 2], M[4, 4], M[5, 5])
    d = (D[0] * fade * (1.0 - 3.0 * u0) + rho * S * cd0 * u0,
         D[1] * fade,
         D[2] + 0.5 * rho * S * u0 * (cla + cd0),
         D[4],
         D[5])
    if min(d) < 0.0:
        raise ValueError(f"vehicle.u0: the linearisation of {pr.name} at {u0:g} m/s has negative damping "
                         f"d = {[round(x, 6) for x in d]}; choose another vehicle.u0 (got {u0!r})")
    src = f"reduction of the Fossen-type torpedo {origin or pr.name} (auvtrack/plant/sixdof/torpedo_reduction.py)"
    return {
        "m": tuple(float(x) for x in m), "d": tuple(float(x) for x in d), "wgml": float(dd["gm"]),
        "sources": {
            "m": {"unit": "kg, kg, kg, kg m^2, kg m^2",
                  "source": f"{src}: diagonal of M_RB + M_A about the CO (u, v, w, q, r); off-diagonal m z_g dropped"},
            "d": {"unit": "N s/m (surge, sway, heave); N m s/rad (pitch, yaw)",
                  "source": f"{src}: D11 e^(-3U0)(1 - 3U0) + rho S CD_0 U0, D22 e^(-3U0), D33 + rho S U0 "
                            f"(CL_alpha + CD_0)/2, D55, D66 at U0 = {u0:.6g} m/s"},
            "wgml": {"unit": "N m", "source": f"{src}: W z_g - B z_b (Prestero 2001 eq. 9.7)"},
        },
    }


TORPEDO_PRESETS: tuple[str, ...] = ("remus100_fossen", "remus600")
"""Shipped Fossen-type 6-DOF files offered as 5-DOF design presets."""


def torpedo_source(name: object) -> str | None:
    """The vehicle file a 5-DOF preset name is reduced from, or None.

    A ``.toml`` path is its own file; a name of :data:`TORPEDO_PRESETS` is a shipped Fossen-type
    6-DOF file.
    """
    from ...vehicle.vehicle_file import is_vehicle_ref, shipped_dir

    if is_vehicle_ref(name):
        return str(name)
    if name in TORPEDO_PRESETS:
        return str(shipped_dir() / f"{name}.toml")
    return None


def torpedo_preset(name: str, u0: float | None) -> VehiclePreset:
    """A Fossen-type torpedo's 5-DOF design model at ``u0`` (default: its file's ``design.u0``).

    Parameters
    ----------
    name : str
        A name of :data:`TORPEDO_PRESETS` or a vehicle file's path.
    u0 : float or None
        Linearisation speed, m/s.

    Returns
    -------
    VehiclePreset
        The reduced numbers with their sources, and the actuators' reach at ``u0``
        (:func:`auvtrack.plant.sixdof.reach.reach_at`).
    """
    from ...vehicle.vehicle_file import label, load_vehicle_file

    path = torpedo_source(name)
    pr = load_vehicle_file(path)
    speed = pr.values["design.u0"] if u0 is None else u0
    from .reach import reach_at

    red = reduce_torpedo(pr, speed, origin=name if name in TORPEDO_PRESETS else label(path))
    l_src = pr.record["design"]["l"]
    reach, reach_src = reach_at(name if name in TORPEDO_PRESETS else path, speed)
    return VehiclePreset(name=name, description=f"{pr.description} (5-DOF reduction at U0)".strip(),
                         m=red["m"], d=red["d"], wgml=red["wgml"], l=float(pr.values["design.l"]),
                         sources={**red["sources"], "l": {"unit": "m", "source": l_src["source"]},
                                  "reach": {"unit": "N, N m, N m", "source": reach_src}}, u0=speed, reach=reach)


SOURCE = PresetSource(names=lambda: TORPEDO_PRESETS, accepts=lambda name: torpedo_source(name) is not None,
                      get=torpedo_preset)
"""The design presets the 6-DOF truths contribute (registered by :mod:`auvtrack.plant.sixdof`)."""
