"""Adaptive RBF network estimating the lumped disturbance chi (paper eq. 11-13, 33, 34).

chi_hat_i = W_i^T psi(x),  psi_j(x) = exp(-||x - c_j||^2 / (2 b^2)),  x = [e, e_dot] in R^6,
with m Gaussian neurons shared by the three axes and one weight vector W_i in R^m per axis.
Adaptive laws (ERRATA 14, docs/derivation.md section 5):

* ``printed``   (eq. 34 as printed):          W_i_dot = psi S_i - W_i (W_i^T W_i)
* ``omega``     (Omega-weighted, ERRATA 14):  W_i_dot = Omega_i psi S_i - W_i (W_i^T W_i)
* ``effective`` (Lyapunov-consistent):        W_i_dot = G_i psi S_i - W_i (W_i^T W_i)

chi enters S_dot multiplied by the effective gain G_i = Omega_i - c1_i of the control law,
S_i_dot = nu_i + G_i (chi_i - chi_hat_i) (c1_i = 0 outside the band of the risk monitor's
gamma, where loop 2 of ERRATA 10 is active); only the G-weighted law cancels the cross term
of Theorem 1's Lyapunov function everywhere.  ``omega`` equals ``effective`` outside the band.
Centres and initial weights are drawn from the scenario seed (stream "rbf") as in Section 4:
centres uniform in [-1, 1], weights uniform in [0, 1].
"""
from __future__ import annotations

import numpy as np

from ...jit import njit_noalloc
from ...jit.vecmath import exp8
from ..._seeding import rng

NONE, PRINTED, OMEGA, EFFECTIVE = 0, 1, 2, 3
ESTIMATORS = {"none": NONE, "printed": PRINTED, "omega": OMEGA, "effective": EFFECTIVE}
N_INPUT = 6


@njit_noalloc(inline="always")
def _exponent(e, ed, cp, off, j, m, inv):
    """-||x - c_j||^2 / (2 b^2) of neuron j (eq. 12), 0 for a padding lane j >= m."""
    if j >= m:
        return 0.0
    d2 = 0.0
    for k in range(3):
        a = e[k] - cp[off + j * N_INPUT + k]
        b = ed[k] - cp[off + j * N_INPUT + 3 + k]
        d2 += a * a + b * b
    return -d2 * inv


@njit_noalloc(inline="always")
def basis(e, ed, cp, off, m, width, psi):
    """Gaussian basis psi(x) of eq. (12), x = [e, e_dot], written to psi[0:m].

    psi_j = exp(-||x - c_j||^2 / (2 b^2)), b = ``width``, eight neurons per
    :func:`auvtrack.jit.vecmath.exp8` (two 4-lane libmvec calls, within 4 ulp of libm's exp).  The centres are
    ``cp[off : off + 6 m]``, row j = (c_e (3), c_e_dot (3)).
    """
    inv = 1.0 / (2.0 * width * width)
    for j0 in range(0, m, 8):
        r = exp8((_exponent(e, ed, cp, off, j0, m, inv), _exponent(e, ed, cp, off, j0 + 1, m, inv),
                  _exponent(e, ed, cp, off, j0 + 2, m, inv), _exponent(e, ed, cp, off, j0 + 3, m, inv),
                  _exponent(e, ed, cp, off, j0 + 4, m, inv), _exponent(e, ed, cp, off, j0 + 5, m, inv),
                  _exponent(e, ed, cp, off, j0 + 6, m, inv), _exponent(e, ed, cp, off, j0 + 7, m, inv)))
        for k in range(min(8, m - j0)):
            psi[j0 + k] = r[k]


@njit_noalloc(inline="always")
def estimate_and_adapt(X, off, m, psi, S_i, gain, dX):
    """chi_hat_i = W^T psi (eq. 33, m/s^2) with W = X[off : off + m]; dX gets W_dot (eq. 34).

    W_dot = gain psi S_i - W (W^T W), gain = 1 (printed law), Omega_i (Omega-weighted law) or
    G_i = Omega_i - c1_i (the effective gain, Lyapunov-consistent law).
    """
    chat, w2 = 0.0, 0.0
    for j in range(m):
        k = np.uintp(off + j)  # unsigned index: no negative-index wraparound, so no gather/scatter
        chat += X[k] * psi[j]
        w2 += X[k] * X[k]
    for j in range(m):
        k = np.uintp(off + j)
        dX[k] = gain * psi[j] * S_i - X[k] * w2
    return chat


@njit_noalloc(inline="always")
def estimate_and_adapt3(X, off, m, psi, S, gain, dX):
    """:func:`estimate_and_adapt` (eq. 33-34) of the three axes in one pass over the neurons.

    The law's form; the same operations in the same order per axis, so bit-identical to three
    :func:`estimate_and_adapt` calls (``tests/engine/test_vecmath.py``).  Axis i's weights are
    X[off + i m : off + (i + 1) m]; S (m/s) and gain are 3-tuples; returns chi_hat (m/s^2).
    """
    c0 = c1 = c2 = 0.0
    n0 = n1 = n2 = 0.0
    for j in range(m):
        k = np.uintp(off + j)
        p = psi[j]
        a, b, c = X[k], X[k + m], X[k + 2 * m]
        c0 += a * p
        c1 += b * p
        c2 += c * p
        n0 += a * a
        n1 += b * b
        n2 += c * c
    for j in range(m):
        k = np.uintp(off + j)
        p = psi[j]
        dX[k] = gain[0] * p * S[0] - X[k] * n0
        dX[k + m] = gain[1] * p * S[1] - X[k + m] * n1
        dX[k + 2 * m] = gain[2] * p * S[2] - X[k + 2 * m] * n2
    return c0, c1, c2


def draw_network(seed: int, neurons: int, centre_range, weight_range) -> tuple[np.ndarray, np.ndarray]:
    """Seeded centres (m, 6) and initial weights (3, m) of the network."""
    g = rng(seed, "rbf")
    centres = g.uniform(centre_range[0], centre_range[1], size=(neurons, N_INPUT))
    weights = g.uniform(weight_range[0], weight_range[1], size=(3, neurons))
    return centres, weights
