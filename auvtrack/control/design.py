"""Gains designed for the vehicle: the closed-loop bandwidth its actuators can deliver at cruise speed.

Every tau law here closes the loop on the error double integrator e_ddot = a + chi of the
nominal model (tracking.py), so each gain has a time dimension n (units s^-n, docs/controllers.md,
"Gains designed for the vehicle").  Scaling every gain g by omega^n (omega > 0, dimensionless)
scales the law in time: the nominal closed loop from a given error e(0) is e(t) = e_1(omega t),
e_1 the response of the unscaled gains, so the demanded error acceleration is omega^2 a_1(omega t)
(D1).  The rule:

    A     = min over the pitch and yaw axes of  ell * R_j / m_j                     (D2, m/s^2)
    a_pk  = max_t |a_1(t)|  of the law's defaults, from e(0) = e_ref, e_dot(0) = 0   (D3, m/s^2)
    omega = min(1, sqrt(kappa A / a_pk))                                            (D4)

R_j (N m) is the moment the fins produce at their limit at the cruise speed U0 (the design
vehicle's ``reach``, :class:`auvtrack.vehicle.presets.VehiclePreset`), m_j = m44, m55 and ell the
virtual point's lever (J3 maps a pitch or yaw acceleration to ell times a virtual-point
acceleration), so A is the largest depth or cross-track error acceleration the fins can give;
e_ref = :data:`DESIGN_ERROR` and kappa = :data:`REACH_FRACTION` (the share of the reach the feedback
may use; the rest is left to trim, turns and disturbances).  The defaults (omega = 1) are the upper end: a vehicle that can do
more keeps them.  The surge axis does not enter (D2): its error is along the path, a timing
error, and on the REMUS 100 the propeller's margin over the drag at cruise is a few newtons,
which would slow the depth and cross-track loops to the propeller's pace; a surge command
beyond the reach is what the compensated forms are for (:mod:`auvtrack.control.saturation`).

The design also selects ``saturation = "compensated"`` (the FTSMC, without internal state, has no
such field).  It applies when the scenario's design
vehicle has a reach and the ``[controller]`` section names no gain (only ``kind`` and
``saturation``) and no gain preset (:mod:`auvtrack.scenario.designed`).  The FXTNTSMC keeps the
paper's gains (its envelope lives in other sections); only its saturation form is chosen.
"""
from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np


DESIGN_ERROR = 0.25
"""e_ref of (D3), m: the error the loop should meet without asking more than the reach (half the
0.5 m start offset of the benchmark's and the model-gap study's tasks: the start saturates, which
the compensated forms handle; the errors of steady operation do not).  A choice, made with the
model-gap study's calm runs in view (docs/controllers.md, "Gains designed for the vehicle")."""
REACH_FRACTION = 1.0
"""kappa of (D4)."""
DESIGN_AXES = (1, 2)
"""The axes of the reach that enter (D2): pitch (tau_q) and yaw (tau_r)."""
PEAK_HORIZON = 40.0
"""s: the span of the unscaled closed loop searched for the peak demand (D3)."""
PEAK_DT = 0.01
"""s: its RK4 step."""



def _spec(kind: str):
    from . import CONTROLLERS
    return CONTROLLERS[kind]


def designed(kind: str) -> bool:
    """Whether the rule sizes the gains of ``kind`` (its module declares ``TIME_EXPONENTS``)."""
    return _spec(kind).time_exponents is not None


def designable(kind: str) -> bool:
    """Whether a vehicle with a reach changes the defaults of ``kind``: designed gains or a saturation form."""
    spec = _spec(kind)
    return spec.time_exponents is not None or spec.has_saturation_forms


def designed_kinds() -> list[str]:
    """The registered laws whose gains the rule sizes, in registration order."""
    from . import CONTROLLERS
    return [k for k in CONTROLLERS if designed(k)]


def designable_kinds() -> list[str]:
    """The registered laws a vehicle with a reach changes (:func:`designable`), in registration order."""
    from . import CONTROLLERS
    return [k for k in CONTROLLERS if designable(k)]


@dataclass(frozen=True)
class GainDesign:
    """The outcome of the rule for one law and one vehicle.

    Attributes
    ----------
    kind : str
        The law.
    accel : float
        A of (D2), m/s^2.
    peak : float
        a_pk of (D3), m/s^2.
    omega : float
        The time scale of (D4).
    gains : dict
        The designed ``[controller]`` fields (with ``saturation = "compensated"`` where the law has the field).
    """

    kind: str
    accel: float
    peak: float
    omega: float
    gains: dict

    def record(self) -> dict:
        """The design as a JSON-ready dict (for ``run.json``)."""
        return {"kind": self.kind, "reach_accel": self.accel, "peak_demand": self.peak, "omega": self.omega,
                "design_error": DESIGN_ERROR, "reach_fraction": REACH_FRACTION, "gains": dict(self.gains)}


def reach_acceleration(m, ell: float, reach) -> float:
    """A of (D2): the least error acceleration the pitch and yaw reach gives, m/s^2.

    Parameters
    ----------
    m : sequence of 5 float
        The design model's m11, m22, m33 (kg), m44, m55 (kg m^2).
    ell : float
        Virtual-point offset, m.
    reach : sequence of 3 float
        (tau_u (N), tau_q, tau_r (N m)) the actuators produce at their limits at cruise speed.

    Returns
    -------
    float
        min(ell R_q / m44, ell R_r / m55).
    """
    return min(ell * abs(float(reach[j])) / float(m[j + 2]) for j in DESIGN_AXES)


def _rk4_peak(f, x0: np.ndarray) -> float:
    """max |a| along x' = f(t, x) (f returns (x', a)) over :data:`PEAK_HORIZON` from x0, RK4 step :data:`PEAK_DT`."""
    x, t, h, peak = np.array(x0, dtype=float), 0.0, PEAK_DT, 0.0
    for _ in range(int(round(PEAK_HORIZON / PEAK_DT))):
        k1, a = f(t, x)
        peak = max(peak, abs(a))
        k2 = f(t + h / 2, x + h / 2 * k1)[0]
        k3 = f(t + h / 2, x + h / 2 * k2)[0]
        k4 = f(t + h, x + h * k3)[0]
        x = x + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
        t += h
    return peak


@functools.lru_cache(maxsize=None)
def peak_demand(kind: str) -> float:
    """a_pk of (D3) for a law's defaults: the largest |e_ddot| its nominal closed loop demands, m/s^2.

    Parameters
    ----------
    kind : str
        A law with a design (:func:`designed`).

    Returns
    -------
    float
        The peak over the three axes (they differ where a law's parameters are per axis).
    """
    spec = _spec(kind)
    p = spec.params()
    return max(_rk4_peak(*spec.nominal_axis(p, i, DESIGN_ERROR)) for i in range(3))


def scaled_gains(kind: str, omega: float) -> dict:
    """The law's default gains scaled in time by ``omega`` (D1): g -> g omega^n.

    Parameters
    ----------
    kind : str
        A law with a design (:func:`designed`).
    omega : float
        The time scale (> 0).

    Returns
    -------
    dict
        Field -> value for every gain of the law's ``TIME_EXPONENTS``.
    """
    spec = _spec(kind)
    p = spec.params()
    out = {}
    for name, n in spec.time_exponents.items():
        power = n(p) if callable(n) else n
        out[name] = float(getattr(p, name)) * omega ** power
    return out


def design(kind: str, m, ell: float, reach) -> GainDesign:
    """The rule (D2)-(D4) for one law on one design vehicle.

    Parameters
    ----------
    kind : str
        A law that :func:`designable` accepts (one with only a saturation form, like the FXTNTSMC,
        gets only that form).
    m : sequence of 5 float
        The design model's inertias (kg, kg m^2).
    ell : float
        Virtual-point offset, m.
    reach : sequence of 3 float
        The design vehicle's reach at cruise speed (N, N m, N m).

    Returns
    -------
    GainDesign
        A, a_pk, omega and the ``[controller]`` fields to use.

    Raises
    ------
    ValueError
        A reach that is not positive on the pitch and yaw axes (one line naming it).
    """
    sat = {"saturation": "compensated"} if _spec(kind).has_saturation_forms else {}
    accel = reach_acceleration(m, ell, reach)
    if not (accel > 0.0 and math.isfinite(accel)):
        raise ValueError(f"vehicle: the fins' reach at cruise speed must be > 0 on pitch and yaw to design gains "
                         f"(got {list(reach)})")
    if not designed(kind):
        return GainDesign(kind, accel, math.nan, 1.0, sat)
    peak = peak_demand(kind)
    omega = min(1.0, math.sqrt(REACH_FRACTION * accel / peak))
    return GainDesign(kind, accel, peak, omega, {**scaled_gains(kind, omega), **sat})
