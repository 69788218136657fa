"""FXTNTSMC: the paper's fixed-time nonsingular terminal SMC (eq. 26-32, corrected).

Per axis i, with z the transformed error of eq. (17) and the envelope of
:mod:`auvtrack.control.fxtntsmc.envelopes`:

    S   = z_dot + S1(S_e),  S_e = a1 sig^a2(z) + a3 sig^a4(z)                   (eq. 26, 28)
    S1  = sig^alpha(S_e) if |S_e| > sigma, else beta1 S_e + beta2 sign(S_e) S_e^2   (eq. 27)
    nu  = -kappa1 sign S - kappa2 sig^3 S - kappa3 S                            (reaching law)

The input makes S_dot = nu + G (chi - chi_hat) (ERRATA 13, derivation in docs/derivation.md):
from z_ddot = Omega_dot e_dot + Omega e_ddot - U_dot e - U e_dot with U_dot e = c0 + c1 e_ddot,

    e_ddot* = [nu - S1_dot - Omega_dot e_dot + c0 + U e_dot] / G,  G = Omega - c1   (G^-1 on nu)
    tau_bar = M_bar J3^-1 (e_ddot* - chi_hat - J3_dot v1 - J4_dot + eta_d_ddot) + C_bar v1 + D_bar v1 + G_bar

where U_dot contains e_ddot itself (loop 2 of ERRATA 10), solved in closed form; G is the
effective gain (= Omega outside the band of the risk monitor's gamma, where c1 = 0).
The |z|^(a2-1) of S1_dot (ERRATA 12) is handled by ``surface``: "nonsingular" replaces
sig^a2(z) for |z| <= z_switch by the C1 quadratic c1 z + c2 sign(z) z^2 (the same device as
eq. 27); "printed" keeps eq. (28) and floors |z| at z_floor inside |z|^(a2-1).

With ``saturation = "compensated"`` an auxiliary system carries the part of the error that the
actuators could not remove, and the whole law (envelope, surface, reaching law, estimator) acts on
the rest, the compensated error e~ (docs/derivation.md section 7):

    lam_ddot = -2 k_aux lam_dot - k_aux^2 lam + d_a,   e~ = e - lam                 (C1)
    a        = e_ddot*(e~, e~_dot) - chi_hat - 2 k_aux lam_dot - k_aux^2 lam          (C2)

with d_a = J3 M_bar^-1 (sat(tau) - tau) the error acceleration the actuators' reach removes on the
nominal model (:mod:`auvtrack.control.saturation`) and e_ddot*, chi_hat the published law's
(eq. 26-34) evaluated at e~.  Then e~_ddot = e_ddot*(e~) - chi_hat + chi whatever the actuators do:
S of e~ obeys the published S_dot = nu + G (chi - chi_hat), and the estimator adapts on it, not on
the error the saturation caused; lam = 0 without saturation, where (C1)-(C2) are the published law
exactly.  The modified tracking error of Farrell, Polycarpou, Sharma & Dong (2009, IEEE TAC 54(6)),
with an auxiliary system driven by the input deficit as in Chen, Ge & Ren (2011, Automatica 47(3))
in its linear form (their extra term for a Lyapunov bound is not used).  The same auxiliary
system as the PPC's (R5)-(R6).

Internal state xc = [rho_bar (3), W (3 x m)], then lam (3, m) and lam_dot (3, m/s) when compensated.
Logged aux channels per axis: rho (envelope),
rho1 (baseline envelope), chi_hat (estimate), sliding (S, the sliding variable), g (envelope trigger),
zeta (z, the transformed error) and gain_ratio (G/Omega: the effective gain G = Omega - c1 with
which chi enters S_dot, over Omega of eq. 18; 1 outside the risk monitor's band); when compensated
also sat_comp (lam of C1).
"""
from __future__ import annotations


from typing import Literal

import numpy as np
from pydantic import Field

from ...jit import njit, njit_noalloc
from ...jit.vecmath import atanh4, pow4
from ...packing import packed_layout
from . import envelopes
from . import rbf
from ..registry import CompiledController, ControllerParams, tunable
from ..contract import WORK_SIZE
from ..saturation import COMPENSATED, SATURATION, accel_deficit, code
from ..tracking import error_state_forces, input_for_accel_forces, sign

NAME = "fxtntsmc"
AXES = ("x", "y", "z")
SECTIONS = ("envelope", "estimator")
AUX = packed_layout("FXTNTSMCChannels", rho=3, rho1=3, chi_hat=3, sliding=3, g=3, zeta=3, gain_ratio=3)
"""Logged channels per axis: envelope rho and its baseline rho1, the estimate chi_hat, the sliding
variable S, the risk indicator g, the transformed error zeta (eq. 17) and G/Omega."""
AUX_NAMES = tuple(f"{n}_{a}" for n in AUX.names for a in AXES)
COMPENSATION_NAMES = tuple(f"sat_comp_{a}" for a in AXES)
"""Channels added when compensated: lam of (C1)."""

GAINS = packed_layout("FXTNTSMCParams", kappa1=1, kappa2=1, kappa3=1, a1=1, a2=1, a3=1, a4=1, alpha=1, sigma=1,
                      surface=1, z_switch=1, z_floor=1, envelope=1, envelope_params=envelopes.PARAMS.size,
                      c1=1, c2=1, beta1=1, beta2=1, estimator=1, neurons=1, width=1, k_aux=1, saturation=1,
                      centres=None)
"""Packed parameters (:func:`setup`): the gains, the envelope kind and its parameters
(:func:`envelopes.axis_transform`), constants precomputed from the gains (c1, c2 of the
nonsingular quadratic, :func:`surface_coeffs`; beta1, beta2 of eq. 27, :func:`switch_coeffs`), the
estimator, the saturation form with its k_aux, and the 6 m RBF centres."""
STATE = packed_layout("FXTNTSMCState", rho_bar=3, weights=None)
"""Internal state xc: the envelope filters rho_bar (3), then the RBF weights W (3 m), then (lam, lam_dot) (6) when compensated."""
SURFACES = {"nonsingular": 0, "printed": 1}
MAX_NEURONS = WORK_SIZE  # the basis psi occupies work[0:m]


class Params(ControllerParams):
    """Fixed-time nonsingular terminal SMC of the paper (eq. 26-32, corrected per ERRATA 11-13).

    Names follow the paper: ``a3 = b1`` and ``a4 = b2`` (ERRATA 11); ``varsigma1`` is the
    approximation-error bound written "zeta1 = 0.05" in Section 4.
    """

    kind: Literal["fxtntsmc"] = "fxtntsmc"
    kappa1: float = tunable(0.005, 1e-4, 1.0, log=True, gt=0, description="switching gain")
    kappa2: float = tunable(0.8, 0.01, 20.0, log=True, gt=0, description="cubic reaching gain")
    kappa3: float = tunable(0.6, 0.01, 20.0, log=True, gt=0, description="linear reaching gain")
    a1: float = tunable(0.8, 0.01, 20.0, log=True, gt=0)
    a2: float = tunable(0.8, 0.5, 0.99, gt=0, lt=1, description="fractional power, 0.5 <= a2 < 1 in Theorem 1")
    a3: float = tunable(0.8, 0.01, 20.0, log=True, gt=0, description="b1 of Theorem 1")
    a4: float = tunable(2.0, 1.05, 5.0, gt=1, description="b2 of Theorem 1")
    alpha: float = tunable(0.6, 0.5, 1.2, gt=0)
    sigma: float = Field(0.005, gt=0, description="switch threshold of eq. (27)")
    varsigma1: float = Field(0.05, gt=0, description="RBF approximation-error bound (Theorem 1)")
    surface: Literal["nonsingular", "printed"] = Field(
        "nonsingular",
        description="'nonsingular': C1 switch on |z| replaces sig^a2 near 0 (ERRATA 12); "
        "'printed': eq. (28) as printed, with |z| floored at z_floor",
    )
    z_switch: float = Field(0.01, gt=0, description="|z| below which the nonsingular switch is used")
    z_floor: float = Field(1e-6, gt=0, description="floor on |z| in the printed form's |z|^(a2-1)")
    k_aux: float = tunable(1.0, 0.01, 10.0, log=True, gt=0, description="rate of the auxiliary system (C1), 1/s (saturation = 'compensated')")
    saturation: Literal[SATURATION] = Field(
        "published", description="'published': eq. (26)-(34); 'compensated': the law on the error less the "
        "auxiliary system's response to what the actuators could not produce (C1)-(C2)")



class StartOutsideEnvelope(ValueError):
    """The initial error lies on or outside the envelope and the start treatment is off."""


@njit
def surface_coeffs(a2, zs):
    """c1, c2 of the C1 quadratic c1 z + c2 sign(z) z^2 that replaces sig^a2(z) for |z| <= zs.

    Matches value and slope of sig^a2 at |z| = zs (ERRATA 12); constant per run, so the
    compiled law reads them from ``cp`` (packed by :func:`setup`).
    """
    return (2.0 - a2) * zs ** (a2 - 1.0), (a2 - 1.0) * zs ** (a2 - 2.0)


@njit
def switch_coeffs(alpha, sigma):
    """beta1, beta2 of eq. (27): C1 at |S_e| = sigma (S_e dimensionless); constant per run (packed in ``cp``)."""
    return (2.0 - alpha) * sigma ** (alpha - 1.0), (alpha - 1.0) * sigma ** (alpha - 2.0)


@njit
def power_below(x, p):
    """x^(p-1), exactly x when p = 2 (x >= 0; x > 0 when p < 1)."""
    return x if p == 2.0 else x ** (p - 1.0)


@njit
def pow_and_power_below(x, p):
    """(x^p, x^(p-1)) with one pow: x^p = x x^(p-1), and x^(p-1) = x when p = 2.

    x >= 0, and x > 0 when p < 1 (x^(p-1) is infinite at 0; callers stay away from 0 there).
    """
    q = power_below(x, p)
    return x * q, q


@njit_noalloc(inline="always")
def powers_below3(x, p, need):
    """:func:`power_below` of the bases ``x`` (3-tuple) for the lanes where ``need`` (3 booleans) is true.

    Two or three needed powers take one vector call (:func:`auvtrack.jit.vecmath.pow4`), which
    returns every lane within 4 ulp of :func:`power_below`; a single needed power is one scalar
    call (exactly :func:`power_below`) and the other lanes are 1.  p = 2 returns the bases.
    """
    if p == 2.0:
        return x
    n = int(need[0]) + int(need[1]) + int(need[2])
    if n >= 2:
        q = p - 1.0
        r = pow4((x[0], x[1], x[2], 1.0), (q, q, q, q))
        return r[0], r[1], r[2]
    q0 = power_below(x[0], p) if need[0] else 1.0
    q1 = power_below(x[1], p) if need[1] else 1.0
    q2 = power_below(x[2], p) if need[2] else 1.0
    return q0, q1, q2


SURF_QUADRATIC, SURF_POWER, SURF_FLOORED = 0, 1, 2


@njit
def surface_branch(az, printed, zs, zfloor):
    """Which form of sig^a2(z) eq. (28) uses at |z| = az: quadratic, power, or floored (printed only)."""
    if not printed and az <= zs:
        return SURF_QUADRATIC
    return SURF_POWER if az >= zfloor else SURF_FLOORED


@njit
def surface_q(z, a1, a2, a3, a4, printed, zs, zfloor, c1, c2, qa):
    """:func:`surface` given the quadratic's (c1, c2) = surface_coeffs(a2, zs) and qa = power_below(|z|, a2).

    qa is used only on the power branch (:func:`surface_branch`), so a caller may pass any value
    elsewhere.
    """
    az = abs(z)
    s = sign(z)
    branch = surface_branch(az, printed, zs, zfloor)
    if branch == SURF_QUADRATIC:
        g, dg = c1 * z + c2 * s * z * z, c1 + 2.0 * c2 * az
    elif branch == SURF_POWER:
        g, dg = s * (az * qa), a2 * qa
    else:
        g, dg = s * az**a2, a2 * zfloor ** (a2 - 1.0)
    pb, qb = pow_and_power_below(az, a4)
    return a1 * g + a3 * s * pb, a1 * dg + a3 * a4 * qb


@njit
def surface_c(z, a1, a2, a3, a4, printed, zs, zfloor, c1, c2):
    """:func:`surface` with the quadratic's coefficients (c1, c2) = surface_coeffs(a2, zs) given."""
    return surface_q(z, a1, a2, a3, a4, printed, zs, zfloor, c1, c2, power_below(abs(z), a2))


@njit
def surface(z, a1, a2, a3, a4, printed, zs, zfloor):
    """S_e(z) of eq. (28) and dS_e/dz, singular-free unless ``printed`` (ERRATA 12).

    S_e = a1 sig^a2(z) + a3 sig^a4(z); "nonsingular": sig^a2 -> c1 z + c2 sign(z) z^2 for
    |z| <= zs; "printed": |z|^(a2-1) -> max(|z|, zfloor)^(a2-1) in the derivative.
    """
    c1, c2 = surface_coeffs(a2, zs)
    return surface_c(z, a1, a2, a3, a4, printed, zs, zfloor, c1, c2)


@njit
def switch_q(se, alpha, sigma, b1, b2, qs):
    """:func:`switch` given (beta1, beta2) = switch_coeffs(alpha, sigma) and qs = power_below(|S_e|, alpha).

    qs is used only where |S_e| > sigma.
    """
    a = abs(se)
    if a > sigma:
        return sign(se) * (a * qs), alpha * qs
    return b1 * se + b2 * sign(se) * se * se, b1 + 2.0 * b2 * a


@njit
def switch_c(se, alpha, sigma, b1, b2):
    """:func:`switch` with (beta1, beta2) = switch_coeffs(alpha, sigma) given."""
    return switch_q(se, alpha, sigma, b1, b2, power_below(abs(se), alpha))


@njit
def switch(se, alpha, sigma):
    """S1(S_e) of eq. (27) and its derivative; C1 at |S_e| = sigma.

    S1 = sig^alpha(S_e) for |S_e| > sigma, else beta1 S_e + beta2 sign(S_e) S_e^2.
    """
    b1, b2 = switch_coeffs(alpha, sigma)
    return switch_c(se, alpha, sigma, b1, b2)


@njit
def reaching_law(S, k1, k2, k3):
    """nu = -kappa1 sign(S) - kappa2 sig^3(S) - kappa3 S of eq. (32), the desired S_dot (S in m/s, nu in m/s^2)."""
    return -k1 * sign(S) - k2 * S * S * S - k3 * S


@njit_noalloc(inline="always")
def _transform(kind, shape, cp, eprm, e, ed, xc, i):
    """Envelope and error transformation of axis ``i`` (eq. 17-25) with xi for z, :func:`envelopes.axis_transform_xi`."""
    r1 = envelopes.axis_baseline(shape, cp, GAINS.envelope_params, i)
    return envelopes.axis_transform_xi(kind, e[i], ed[i], xc[STATE.rho_bar + i], eprm, r1)


@njit_noalloc(inline="always")
def _finish_axis(i, tr, z, se, dse, qs, ed_i, cp, dxc, aux):
    """Axis ``i`` after its S_e (eq. 28): S (eq. 26-27) and the commanded e_ddot (eq. 32, ERRATA 13).

    Returns (S (m/s), e_ddot (m/s^2), Omega_i, G_i), G_i = Omega_i - c1_i the effective gain with
    which chi enters S_dot (1/m, as Omega); writes dxc of rho_bar_i and the aux channels except
    chi_hat, which the estimator's update of the three axes fills in afterwards.
    """
    _, zd, Om, U, Omd, c0, c1, rho, rbd, rho1, g = tr
    s1, dphi = switch_q(se, cp[GAINS.alpha], cp[GAINS.sigma], cp[GAINS.beta1], cp[GAINS.beta2], qs)
    S = zd + s1
    reach = reaching_law(S, cp[GAINS.kappa1], cp[GAINS.kappa2], cp[GAINS.kappa3])
    G = Om - c1  # > 0 (docs/derivation.md section 3)
    edd = (reach - dphi * dse * zd - Omd * ed_i + c0 + U * ed_i) / G
    dxc[STATE.rho_bar + i] = rbd
    aux[AUX.rho + i], aux[AUX.rho1 + i], aux[AUX.sliding + i], aux[AUX.g + i], aux[AUX.zeta + i] = rho, rho1, S, g, z
    aux[AUX.gain_ratio + i] = G / Om  # exactly 1 where c1 = 0
    return S, edd, Om, G


@njit_noalloc(inline="always")
def control(t, y, xc, args, out):
    """Compiled FXTNTSMC law, eq. (26)-(34) corrected (tau in N, N m); status 1 if an error leaves its envelope.

    ``args.work[0:m]`` holds the RBF basis.
    """
    cp, work, dxc, aux = args.cp, args.work, out.dxc, out.aux
    e, ed, f, gf = error_state_forces(y.eta, y.att, y.nu, args.ref, args.vp)
    kind, est, m = int(cp[GAINS.envelope]), int(cp[GAINS.estimator]), int(cp[GAINS.neurons])
    comp = cp[GAINS.saturation] == COMPENSATED
    off = STATE.weights + 3 * m  # (lam, lam_dot) of (C1), when compensated
    if comp:  # the law acts on e~ = e - lam (C2)
        e = (e[0] - xc[off], e[1] - xc[off + 1], e[2] - xc[off + 2])
        ed = (ed[0] - xc[off + 3], ed[1] - xc[off + 4], ed[2] - xc[off + 5])
    if est != rbf.NONE:
        rbf.basis(e, ed, cp, GAINS.centres, m, cp[GAINS.width], work)
    printed = cp[GAINS.surface] != 0.0
    # the baseline's exp(-t / (T - t)) is shared by the three axes (one T)
    shape = envelopes.AFTER_T
    if kind != envelopes.NONE:
        shape = envelopes.baseline_shape(t, cp[GAINS.envelope_params + envelopes.PARAMS.T])
    eprm = envelopes.params(cp, GAINS.envelope_params)
    # three phases over the axes, so that atanh (eq. 17) and each power of eq. (27)-(28) is one vector call
    st0, tr0 = _transform(kind, shape, cp, eprm, e, ed, xc, 0)
    if st0 != 0:
        return st0
    st1, tr1 = _transform(kind, shape, cp, eprm, e, ed, xc, 1)
    if st1 != 0:
        return st1
    st2, tr2 = _transform(kind, shape, cp, eprm, e, ed, xc, 2)
    if st2 != 0:
        return st2
    xi = (tr0[0], tr1[0], tr2[0])  # e / rho, or e itself without an envelope (then z = e)
    z = xi
    if kind != envelopes.NONE:
        zv = atanh4((xi[0], xi[1], xi[2], 0.0))  # z = atanh(xi), eq. (17)
        z = (zv[0], zv[1], zv[2])
    az = (abs(z[0]), abs(z[1]), abs(z[2]))
    need = (surface_branch(az[0], printed, cp[GAINS.z_switch], cp[GAINS.z_floor]) == SURF_POWER,
            surface_branch(az[1], printed, cp[GAINS.z_switch], cp[GAINS.z_floor]) == SURF_POWER,
            surface_branch(az[2], printed, cp[GAINS.z_switch], cp[GAINS.z_floor]) == SURF_POWER)
    qz = powers_below3(az, cp[GAINS.a2], need)
    se0, dse0 = surface_q(z[0], cp[GAINS.a1], cp[GAINS.a2], cp[GAINS.a3], cp[GAINS.a4], printed, cp[GAINS.z_switch], cp[GAINS.z_floor], cp[GAINS.c1], cp[GAINS.c2], qz[0])
    se1, dse1 = surface_q(z[1], cp[GAINS.a1], cp[GAINS.a2], cp[GAINS.a3], cp[GAINS.a4], printed, cp[GAINS.z_switch], cp[GAINS.z_floor], cp[GAINS.c1], cp[GAINS.c2], qz[1])
    se2, dse2 = surface_q(z[2], cp[GAINS.a1], cp[GAINS.a2], cp[GAINS.a3], cp[GAINS.a4], printed, cp[GAINS.z_switch], cp[GAINS.z_floor], cp[GAINS.c1], cp[GAINS.c2], qz[2])
    ase = (abs(se0), abs(se1), abs(se2))
    qs = powers_below3(ase, cp[GAINS.alpha], (ase[0] > cp[GAINS.sigma], ase[1] > cp[GAINS.sigma], ase[2] > cp[GAINS.sigma]))
    S0, edd0, om0, G0 = _finish_axis(0, tr0, z[0], se0, dse0, qs[0], ed[0], cp, dxc, aux)
    S1, edd1, om1, G1 = _finish_axis(1, tr1, z[1], se1, dse1, qs[1], ed[1], cp, dxc, aux)
    S2, edd2, om2, G2 = _finish_axis(2, tr2, z[2], se2, dse2, qs[2], ed[2], cp, dxc, aux)
    chat = (0.0, 0.0, 0.0)
    if est != rbf.NONE:
        gain = (1.0, 1.0, 1.0)  # printed eq. (34)
        if est == rbf.OMEGA:
            gain = (om0, om1, om2)
        elif est == rbf.EFFECTIVE:
            gain = (G0, G1, G2)
        chat = rbf.estimate_and_adapt3(xc, STATE.weights, m, work, (S0, S1, S2), gain, dxc)
    aux[AUX.chi_hat], aux[AUX.chi_hat + 1], aux[AUX.chi_hat + 2] = chat
    acc = (edd0 - chat[0], edd1 - chat[1], edd2 - chat[2])
    if not comp:
        out.u[0], out.u[1], out.u[2] = input_for_accel_forces(y.att, args.vp, f, acc, gf)
        return 0
    k = cp[GAINS.k_aux]
    b0, b1, b2 = (-2.0 * k * xc[off + 3] - k * k * xc[off], -2.0 * k * xc[off + 4] - k * k * xc[off + 1],
                  -2.0 * k * xc[off + 5] - k * k * xc[off + 2])  # the auxiliary system's own part of (C1)
    tau = input_for_accel_forces(y.att, args.vp, f, (acc[0] + b0, acc[1] + b1, acc[2] + b2), gf)
    out.u[0], out.u[1], out.u[2] = tau
    da = accel_deficit(y.att, args.vp, tau, args.lo, args.hi)[0]
    dxc[off], dxc[off + 1], dxc[off + 2] = xc[off + 3], xc[off + 4], xc[off + 5]
    dxc[off + 3], dxc[off + 4], dxc[off + 5] = b0 + da[0], b1 + da[1], b2 + da[2]
    aux[AUX.size], aux[AUX.size + 1], aux[AUX.size + 2] = xc[off], xc[off + 1], xc[off + 2]
    return 0


def start_widening(e0, rho1_0, xi0: float, widen: bool) -> tuple[np.ndarray, list[str]]:
    """Initial rho_bar (ERRATA 9): rho_bar_i(0) = max(0, |e_i(0)| / xi0 - rho1_i(0)).

    Widening applies on every axis where |e_i(0)| / rho1_i(0) > xi0 and is reported; with
    ``widen`` false a start on or outside the envelope (ratio >= 1) raises
    :class:`StartOutsideEnvelope` and a start inside it is left as it is.
    """
    rb = np.zeros(3)
    notes = []
    for i, a in enumerate(AXES):
        ratio = abs(e0[i]) / rho1_0[i]
        if widen and ratio > xi0:
            rb[i] = abs(e0[i]) / xi0 - rho1_0[i]
            notes.append(
                f"envelope: start at |e_{a}(0)|/rho1_{a}(0) = {ratio:.4g} (>= xi0 = {xi0}); "
                f"rho_bar_{a}(0) widened by {rb[i]:.6g} m so that |e_{a}(0)|/rho_{a}(0) = {xi0}"
            )
        elif not widen and ratio >= 1.0:
            raise StartOutsideEnvelope(
                f"envelope: the start lies on or outside the envelope on axis {a} "
                f"(|e_{a}(0)| = {abs(e0[i]):.6g} m >= rho_{a}(0) = {rho1_0[i]:.6g} m); "
                "set envelope.widen_start = true or enlarge envelope.rho0"
            )
    return rb, notes


def setup(params: Params, ctx) -> CompiledController:
    """Pack gains, envelope (``[envelope]``) and network (``[estimator]``); apply the start treatment."""
    p, env, est = params, ctx.section("envelope"), ctx.section("estimator")
    kind = envelopes.ENVELOPES[env.kind]
    rho0, rho_inf = np.asarray(env.rho0, float), np.asarray(env.rho_inf, float)
    printed = env.baseline == "printed"
    notes: list[str] = []
    rb0 = np.zeros(3)
    if kind != envelopes.NONE:
        rho1_0 = np.array([envelopes.baseline(0.0, rho0[i], rho_inf[i], env.T, printed)[0] for i in range(3)])
        rb0, notes = start_widening(ctx.e0, rho1_0, env.xi0, env.widen_start)
    m = est.neurons if est.kind != "none" else 0
    if m > MAX_NEURONS:
        raise ValueError(f"estimator.neurons: at most {MAX_NEURONS} (got {m})")
    centres, weights = rbf.draw_network(ctx.seed, m, est.centre_range, est.weight_range)
    c1, c2 = surface_coeffs(p.a2, p.z_switch)
    beta1, beta2 = switch_coeffs(p.alpha, p.sigma)
    cp = GAINS.pack(kappa1=p.kappa1, kappa2=p.kappa2, kappa3=p.kappa3, a1=p.a1, a2=p.a2, a3=p.a3, a4=p.a4,
                    alpha=p.alpha, sigma=p.sigma, surface=SURFACES[p.surface], z_switch=p.z_switch,
                    z_floor=p.z_floor, envelope=kind,
                    envelope_params=envelopes.PARAMS.pack(
                        T=env.T, delta=env.delta, epsilon=env.epsilon, lambda1=env.lambda1, lambda2=env.lambda2,
                        lambda3=env.lambda3, threshold=env.reactive_threshold, printed=float(printed), rho0=rho0,
                        rho_inf=rho_inf),
                    c1=c1, c2=c2, beta1=beta1, beta2=beta2,
                    estimator=rbf.ESTIMATORS[est.kind], neurons=m, width=est.width, k_aux=p.k_aux,
                    saturation=code(p.saturation), centres=centres.ravel())
    xc0 = STATE.pack(rho_bar=rb0, weights=weights.ravel())
    comp = p.saturation == "compensated"
    if comp:
        xc0 = np.concatenate([xc0, np.zeros(6)])  # lam(0) = lam_dot(0) = 0
    resolved = {"rho_bar0": rb0.tolist(), "rbf_centres": centres.tolist(), "rbf_weights0": weights.tolist()}
    return CompiledController(cp=cp, xc0=xc0, aux_names=AUX_NAMES + (COMPENSATION_NAMES if comp else ()),
                              notes=tuple(notes), resolved=resolved)


def warnings(params: Params) -> list[str]:
    """The conditions of Theorem 1 that ``params`` break (:func:`auvtrack.control.fxtntsmc.theory.check_theorem1`).

    Parameters
    ----------
    params : Params
        The gains.

    Returns
    -------
    list of str
        One line per violated condition.
    """
    from .theory import check_theorem1

    return list(check_theorem1(params))
