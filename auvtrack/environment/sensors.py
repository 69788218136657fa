"""Sensor model: additive white Gaussian noise on the measured state, seeded.

The controller sees ``eta_m = eta + n_eta``, ``nu_m = nu + n_nu`` at each control sample k, with
``n ~ N(0, diag(sigma^2))`` independent across samples and channels:

====  ==================  ======================
index channel             unit of sigma
====  ==================  ======================
0-2    x, y, z             m
3-4    theta, psi          rad
5-7    u, v, w             m/s
8-9    q, r                rad/s
====  ==================  ======================

Noise is sampled once per control sample (it needs ``sim.control_rate > 0``: white noise
inside one RK4 step has no meaning) and drawn from the scenario seed's stream ``"sensor"``
(:mod:`auvtrack._seeding`), so a run stays a pure function of its scenario.  The true state is
integrated and logged; only the controller's view is noisy.
"""
from __future__ import annotations

import numpy as np

from .._seeding import rng
from ..jit import njit_noalloc

N_MEAS = 10


def noise_table(seed: int, n_samples: int, sigma) -> np.ndarray:
    """Draw the noise of every control sample.

    Parameters
    ----------
    seed : int
        Scenario seed (stream ``"sensor"``).
    n_samples : int
        Number of control samples (>= 1).
    sigma : sequence of 10 float
        Standard deviations per channel (see the module table), each >= 0.

    Returns
    -------
    numpy.ndarray
        Shape (n_samples, 10); shape (0, 10) when every sigma is 0 (no noise).

    Raises
    ------
    ValueError
        If ``sigma`` does not have 10 non-negative finite entries or ``n_samples < 1``.
    """
    s = np.asarray(sigma, float).ravel()
    if s.size != N_MEAS or not np.all(np.isfinite(s)) or np.any(s < 0):
        raise ValueError(f"sensor: sigma needs 10 finite values >= 0, got {s.tolist()}")
    if n_samples < 1:
        raise ValueError(f"sensor: n_samples must be >= 1, got {n_samples}")
    if not np.any(s > 0):
        return np.zeros((0, N_MEAS))
    return rng(seed, "sensor").standard_normal((n_samples, N_MEAS)) * s


@njit_noalloc
def measure(eta, nu, noise, k):
    """The controller's view at control sample ``k``: the true (eta, nu) 5-tuples plus row ``k`` of ``noise``.

    With a noise table of no rows (every sigma zero) the measurement is exact.
    """
    if noise.shape[0] == 0:
        return eta, nu
    n = noise
    return ((eta[0] + n[k, 0], eta[1] + n[k, 1], eta[2] + n[k, 2], eta[3] + n[k, 3], eta[4] + n[k, 4]),
            (nu[0] + n[k, 5], nu[1] + n[k, 6], nu[2] + n[k, 7], nu[3] + n[k, 8], nu[4] + n[k, 9]))
