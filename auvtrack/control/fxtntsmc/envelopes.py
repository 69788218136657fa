"""Prescribed-performance envelopes (paper eq. 16-25, corrected per ERRATA 7-10).

Each axis i has the envelope rho = rho1(t) + rho_bar, with the baseline rho1 of eq. (24) and
the adjustment rho_bar, an internal controller state driven by

    rho_bar_dot = -lambda1 rho_bar + lambda2 g tanh(|xi| / lambda3),   xi = e / rho       (eq. 25)

where the trigger g in [0, 1] defines the scheme:

==========  ====  ==============================================================================
scheme      code  trigger g
==========  ====  ==============================================================================
none        0     no envelope: no error transformation (z = e)
rigid       1     g = 0: rho = rho1 (plus the decaying start widening, if any)
reactive    2     g = smoothstep(|xi|) rising from 0 to 1 over [thr - 0.05, thr]: the "passive"
                  schemes the paper argues against, acting once |xi| approaches the bound
proactive   3     g = gamma(hbar) of eq. (22), hbar = zeta_dot + delta zeta, zeta = 1 - xi^2
                  (eq. 20-21): the paper's risk monitor, acting on the predicted trend
==========  ====  ==============================================================================

Algebraic loops (ERRATA 10), both solved exactly here:

1. hbar needs xi_dot, hence rho_dot, which contains g = gamma(hbar).  hbar is affine in g,
   hbar = h0 + k g with k >= 0, and gamma is non-increasing, so g - gamma(h0 + k g) is
   strictly increasing on [0, 1]: one root, found by safeguarded Newton iteration.
2. rho_ddot (needed by U_dot in the control law) depends on e_ddot through hbar_dot, i.e. on
   the input.  It is affine, rho_ddot = p + q e_ddot, and :func:`axis_transform` returns p, q
   so the control law can solve for e_ddot in closed form.
"""
from __future__ import annotations

import math

from ...jit import njit
from ...packing import packed_layout

NONE, RIGID, REACTIVE, PROACTIVE = 0, 1, 2, 3
ENVELOPES = {"none": NONE, "rigid": RIGID, "reactive": REACTIVE, "proactive": PROACTIVE}
REACTIVE_BAND = 0.05


AFTER_T = (0, 0.0, 0.0, 0.0)  # baseline_shape for t >= T


@njit
def baseline_shape(t, T):
    """The time factor of eq. (24), shared by every axis: (state, exp(phi), phi_dot, phi_dot^2 + phi_ddot).

    phi = -t / (T - t); state 0: t >= T (rho1 = rho_inf), 1: exp(phi) underflows, 2: t < T.
    d/dt exp(phi) = exp(phi) phi_dot and d^2/dt^2 exp(phi) = exp(phi) (phi_dot^2 + phi_ddot).
    """
    if t >= T:
        return 0, 0.0, 0.0, 0.0
    s = T - t
    phi = -t / s
    if phi < -700.0:
        return 1, 0.0, 0.0, 0.0
    d1 = -T / (s * s)
    d2 = -2.0 * T / (s * s * s)
    return 2, math.exp(phi), d1, d1 * d1 + d2


@njit
def baseline_from_shape(shape, rho0, rho_inf, printed):
    """rho1, rho1_dot, rho1_ddot of eq. (24) for one axis from :func:`baseline_shape`."""
    state, ex, d1, d11 = shape
    if state == 0:
        return rho_inf, 0.0, 0.0
    if state == 1:
        return (0.0 if printed else rho_inf), 0.0, 0.0
    a = (rho0 - rho_inf) * ex
    # rho_inf <= rho1 <= rho0 exactly: (rho0 - rho_inf) + rho_inf can round one ulp above rho0
    r = a if printed else min(a + rho_inf, rho0)
    return r, a * d1, a * d11


@njit
def baseline(t, rho0, rho_inf, T, printed):
    """Baseline envelope rho1 of eq. (24) and its first two derivatives (m, m/s, m/s^2).

    Corrected (ERRATA 7): rho1 = (rho0 - rho_inf) exp(-t / (T - t)) + rho_inf for t < T,
    rho_inf afterwards; C-infinity at T.  ``printed``: the form as printed, without
    + rho_inf for t < T (decays to 0 at T, then jumps to rho_inf).
    """
    return baseline_from_shape(baseline_shape(t, T), rho0, rho_inf, printed)


@njit
def risk_indicator(h, eps):
    """Smooth indicator gamma(hbar) of eq. (22) and its derivative d gamma / d hbar (hbar and eps in 1/s)."""
    if h <= 0.0:
        return 1.0, 0.0
    if h >= 2.0 * eps:
        return 0.0, 0.0
    s = h / (2.0 * eps)
    return 1.0 - 3.0 * s * s + 2.0 * s * s * s, (-6.0 * s + 6.0 * s * s) / (2.0 * eps)


@njit
def reactive_trigger(a, thr):
    """C1 smoothstep of |xi| = a over [thr - REACTIVE_BAND, thr] and its derivative."""
    lo = thr - REACTIVE_BAND
    if a <= lo:
        return 0.0, 0.0
    if a >= thr:
        return 1.0, 0.0
    s = (a - lo) / REACTIVE_BAND
    return 3.0 * s * s - 2.0 * s * s * s, (6.0 * s - 6.0 * s * s) / REACTIVE_BAND


@njit
def solve_risk_loop(h0, k, eps):
    """Solve g = gamma(h0 + k g) of eq. (21)-(22) on [0, 1] (loop 1 of ERRATA 10); h0, k in 1/s, k >= 0; returns g."""
    lo, hi = 0.0, 1.0
    g, _ = risk_indicator(h0, eps)
    for _ in range(60):
        gam, dgam = risk_indicator(h0 + k * g, eps)
        F = g - gam
        if abs(F) <= 1e-15:
            break
        if F > 0.0:
            hi = g
        else:
            lo = g
        g_new = g - F / (1.0 - k * dgam)  # F' = 1 - k gamma' >= 1
        g = g_new if lo < g_new < hi else 0.5 * (lo + hi)
    return g


PARAMS = packed_layout("EnvelopeParams", T=1, delta=1, epsilon=1, lambda1=1, lambda2=1, lambda3=1, threshold=1,
                       printed=1, rho0=3, rho_inf=3)
"""Packed envelope parameters ``ep[off : off + PARAMS.size]`` (rho0, rho_inf: x, y, z)."""
OUTSIDE = (math.nan,) * 11


@njit
def axis_baseline(shape, ep, off, i):
    """rho1, rho1_dot, rho1_ddot of eq. (24) for axis ``i`` from :func:`baseline_shape`."""
    return baseline_from_shape(shape, ep[off + PARAMS.rho0 + i], ep[off + PARAMS.rho_inf + i], ep[off + PARAMS.printed] != 0.0)


@njit
def axis_transform(kind, t, e, ed, rb, ep, off, i):
    """Envelope and error transformation of axis ``i`` (eq. 17-19, 23-25).

    ``ep[off : off + PARAMS.size]`` in the layout :data:`PARAMS`.  Returns (status, values) with status 1 if |e| >= rho (outside the
    envelope) and values = (z, z_dot, Omega, U, Omega_dot, c0, c1, rho, rho_bar_dot, rho1, g),
    where U_dot e = c0 + c1 e_ddot collects every U_dot term (loop 2 of ERRATA 10), so that
    z_ddot = Omega_dot e_dot + Omega e_ddot - (c0 + c1 e_ddot) - U e_dot.
    """
    prm = params(ep, off)
    if kind == NONE:
        return axis_transform_given(kind, e, ed, rb, prm, (math.nan, 0.0, 0.0))
    r1 = axis_baseline(baseline_shape(t, ep[off + PARAMS.T]), ep, off, i)
    return axis_transform_given(kind, e, ed, rb, prm, r1)


@njit
def _tanh_and_slope(a, lam3):
    """tanh(a / lambda3) of eq. (25) and its derivative in a."""
    il3 = 1.0 / lam3
    th = math.tanh(a * il3)
    return th, (1.0 - th * th) * il3


@njit
def params(ep, off):
    """(delta, eps, lambda1, lambda2, lambda3, thr) from ``ep[off : off + PARAMS.size]`` as a tuple."""
    return (ep[off + PARAMS.delta], ep[off + PARAMS.epsilon], ep[off + PARAMS.lambda1], ep[off + PARAMS.lambda2], ep[off + PARAMS.lambda3],
            ep[off + PARAMS.threshold])


@njit(inline="always")
def axis_transform_given(kind, e, ed, rb, prm, r1):
    """:func:`axis_transform` with prm = :func:`params` and r1 = (rho1, rho1_dot, rho1_ddot) given.

    The compiled law evaluates exp(-t / (T - t)) once for the three axes
    (:func:`baseline_shape`) and passes each axis' :func:`baseline_from_shape`.
    """
    status, tr = axis_transform_xi(kind, e, ed, rb, prm, r1)
    if status != 0 or kind == NONE:
        return status, tr
    return status, (math.atanh(tr[0]),) + tr[1:]  # z = 0.5 ln((1 + xi) / (1 - xi)), eq. (17)


@njit(inline="always")
def axis_transform_xi(kind, e, ed, rb, prm, r1):
    """:func:`axis_transform_given` with xi = e / rho in the place of z = atanh(xi) (e itself for kind "none").

    For the compiled law, which takes atanh of the three axes in one vector call.  Scalars and
    tuples only (no arrays: an array argument costs two atomic reference-count updates per call).
    Divisions by rho, D = rho^2 - e^2, lambda3 and den are multiplications by their reciprocals.
    """
    if kind == NONE:
        return 0, (e, ed, 1.0, 0.0, 0.0, 0.0, 0.0, math.nan, 0.0, math.nan, 0.0)
    delta, eps, lam1, lam2, lam3, thr = prm
    rho1, rho1d, rho1dd = r1
    rho = rho1 + rb
    ir = 1.0 / rho
    xi = e * ir
    if not abs(xi) < 1.0:
        return 1, OUTSIDE
    axi = abs(xi)
    sgn = 1.0 if xi > 0.0 else (-1.0 if xi < 0.0 else 0.0)
    base = rho1d - lam1 * rb
    g, gd_h, gd_a, c_h = 0.0, 0.0, 0.0, 0.0
    # tanh(|xi| / lambda3) of eq. (25) and its derivative only ever multiply g, g' or gamma';
    # they are evaluated where one of these can be non-zero (all are exactly 0 elsewhere)
    th, dth = 0.0, 0.0
    if kind == PROACTIVE:
        # hbar = -2 xi xi_dot + delta (1 - xi^2), xi_dot = e_dot/rho - e rho_dot/rho^2 (eq. 20-21)
        h0 = -2.0 * xi * ed * ir + delta * (1.0 - xi * xi) + 2.0 * xi * xi * ir * base
        if not h0 >= 2.0 * eps:  # else g = gamma(h0 + k g) = 0 exactly, for every k >= 0
            th, dth = _tanh_and_slope(axi, lam3)
            k = 2.0 * xi * xi * ir * lam2 * th
            g = solve_risk_loop(h0, k, eps)
            _, gd_h = risk_indicator(h0 + k * g, eps)
    elif kind == REACTIVE:
        g, gd_a = reactive_trigger(axi, thr)
        if g != 0.0 or gd_a != 0.0:
            th, dth = _tanh_and_slope(axi, lam3)
    rbd = -lam1 * rb + lam2 * g * th
    rhod = rho1d + rbd
    xid = (ed - e * rhod * ir) * ir  # e_dot/rho - e rho_dot/rho^2
    axid = sgn * xid
    # rho_ddot = p + q e_ddot
    rbdd_0 = -lam1 * rbd + lam2 * (g * dth + gd_a * th) * axid
    q = 0.0
    if gd_h != 0.0:  # proactive, inside the band of gamma (otherwise c_h = 0: p = K0, q = 0)
        c_h = lam2 * th * gd_h  # <= 0
        # hbar_dot = -2 xid^2 - 2 xi xidd - 2 delta xi xid, xidd = edd/rho + X0 - e rhodd/rho^2
        ir2 = ir * ir
        X0 = -2.0 * ed * rhod * ir2 + 2.0 * e * rhod * rhod * ir2 * ir
        K0 = rho1dd + rbdd_0 + c_h * (-2.0 * xid * xid - 2.0 * delta * xi * xid)
        iden = 1.0 / (1.0 - 2.0 * c_h * xi * e * ir2)  # den >= 1
        p = (K0 - 2.0 * c_h * xi * X0) * iden
        q = -(2.0 * c_h * xi * ir) * iden
    else:
        p = rho1dd + rbdd_0
    D = rho * rho - e * e
    iD = 1.0 / D
    Om = rho * iD
    U = rhod * iD
    Dd = 2.0 * rho * rhod - 2.0 * e * ed
    Omd = U - Om * Dd * iD  # rho_dot / D - rho Dd / D^2
    # U_dot = rho_ddot / D - rho_dot Dd / D^2, rho_ddot = p + q e_ddot
    c0 = (p - U * Dd) * iD * e
    c1 = q * iD * e
    return 0, (xi, Om * ed - U * e, Om, U, Omd, c0, c1, rho, rbd, rho1, g)
