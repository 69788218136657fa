"""Ocean current as a first-order Gauss-Markov process, and the force it exerts on the AUV.

Model (per NED component j = x, y, z, velocities in m/s)::

    dV_j = -(V_j - mean_j) / tau dt + sqrt(2 / tau) sigma_j dW_j

so V_j is stationary with mean ``mean_j``, standard deviation ``sigma_j`` and autocorrelation
``exp(-|s| / tau)``.  It is sampled on the grid ``t_k = k h`` (``h = sample_dt``) with the exact
discretisation (no Euler error)::

    V_{k+1} = mean + (V_k - mean) e^{-h/tau} + sigma sqrt(1 - e^{-2h/tau}) N(0, 1),

and ``V_0`` is drawn from the stationary distribution N(mean, sigma^2), so the whole series is
stationary from t = 0.  Between samples V is linearly interpolated; before t = 0 and after the
last sample the end value is held.

Force on the vehicle: the linear damping acts on the velocity relative to the water,
``D (nu - nu_c)``, with ``nu_c[0:3] = J1(theta, psi)^T V_c`` the current in the body frame
(irrotational current: no pitch/yaw rate component).  Moving ``D nu_c`` to the right-hand side
of ``M nu_dot + C nu + D nu + G = tau + omega`` gives::

    omega[0:3] = diag(d11, d22, d33) J1(theta, psi)^T V_c(t),   omega[3:5] = 0,

in N, with the damping of the packed ``vp`` passed to the evaluator (the true plant's).  This is
the damping-only current model; the added-mass Coriolis of the relative velocity and the current
acceleration term are neglected.

References
----------
Fossen, T. I. (2021). Handbook of Marine Craft Hydrodynamics and Motion Control, 2nd ed.,
ch. 8 (environmental forces: ocean currents, first-order Gauss-Markov current speed).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from ..jit import njit_noalloc
from ..vehicle.kinematics import attitude, body_from_ned
from ..vehicle.params import VP
from . import _validate as val
from .layout import C_DT, C_N, C_OFFSET, CUR_COLS, KIND_CURRENT, ROW_SIZE

MAX_SAMPLES = 2 ** 31  # hard ceiling per current component; the run plan enforces limits.max_table_rows first


@dataclass(frozen=True, kw_only=True)
class GaussMarkovCurrent:
    """First-order Gauss-Markov ocean current velocity V_c(t) in NED.

    Parameters
    ----------
    mean : sequence of 3 float
        Mean current [north, east, down], m/s.
    sigma : sequence of 3 float
        Stationary standard deviation per component, m/s, >= 0 (0 gives a constant current).
    tau : float
        Correlation time constant, s, > 0.
    sample_dt : float
        Grid step of the generated samples, s, > 0.
    """

    KIND: ClassVar[str] = "current"
    CODE: ClassVar[float] = KIND_CURRENT
    EFFECT: ClassVar[str] = "current"
    TIME_ONLY: ClassVar[bool] = False
    TERM: ClassVar[str] = "current_velocity"

    mean: tuple[float, ...] = (0.0, 0.0, 0.0)
    sigma: tuple[float, ...] = (0.05, 0.05, 0.0)
    tau: float = 60.0
    sample_dt: float = 0.1

    def __post_init__(self) -> None:
        object.__setattr__(self, "mean", val.vector("current", "mean", self.mean, 3,
                                                    rng_text="finite numbers (m/s, NED)"))
        object.__setattr__(self, "sigma", val.vector("current", "sigma", self.sigma, 3, lo=0.0,
                                                     rng_text="finite numbers >= 0 (m/s)"))
        object.__setattr__(self, "tau", val.real("current", "tau", self.tau, lo=0.0, lo_open=True,
                                                 rng_text="a finite real number > 0 (s)"))
        object.__setattr__(self, "sample_dt", val.real(
            "current", "sample_dt", self.sample_dt, lo=0.0, lo_open=True,
            rng_text="a finite real number > 0 (s)"))

    def describe(self) -> dict:
        """JSON-serialisable description of the parameters (not the samples)."""
        return {"kind": "current", "mean": list(self.mean), "sigma": list(self.sigma),
                "tau": self.tau, "sample_dt": self.sample_dt}

    def n_samples(self, duration: float) -> int:
        """Number of grid samples covering ``[0, duration]`` (the last one at or beyond it)."""
        n = math.ceil(duration / self.sample_dt - 1e-9) + 1
        n = max(n, 2)
        if n > MAX_SAMPLES:
            raise ValueError(f"current.sample_dt ({self.sample_dt} s) gives {n} samples over "
                             f"{duration} s; the limit is {MAX_SAMPLES}")
        return n

    def sample(self, duration: float, gen: np.random.Generator) -> np.ndarray:
        """Generate the samples on ``t_k = k sample_dt`` covering ``[0, duration]``.

        Draws one ``(n, 3)`` array of standard normals from ``gen``: row 0 sets the stationary
        initial value, row k the innovation of step k.

        Returns
        -------
        ndarray, shape (n, 4)
            Columns t (s), Vx, Vy, Vz (m/s, NED).
        """
        n = self.n_samples(duration)
        h = self.sample_dt
        mean, sigma = np.array(self.mean), np.array(self.sigma)
        a = math.exp(-h / self.tau)
        c = math.sqrt(-math.expm1(-2.0 * h / self.tau))  # sqrt(1 - a^2), accurate for h << tau
        z = gen.standard_normal((n, 3))
        y0 = sigma * z[0]
        dev = np.empty((n, 3))
        dev[0] = y0
        # AR(1) y_k = a y_{k-1} + c sigma z_k, run by lfilter with initial condition a y_0
        from scipy.signal import lfilter  # imported here: scipy.signal costs a second at every start

        dev[1:], _ = lfilter([c], [1.0, -a], sigma * z[1:], axis=0, zi=(a * y0)[None, :])
        out = np.empty((n, CUR_COLS))
        out[:, 0] = h * np.arange(n)
        out[:, 1:] = mean + dev
        return out

    def pack_row(self, offset: int, n: int) -> np.ndarray:
        """Packed row pointing at ``n`` samples starting at row ``offset`` of the current table."""
        row = np.zeros(ROW_SIZE)
        row[0], row[C_OFFSET], row[C_N], row[C_DT] = KIND_CURRENT, offset, n, self.sample_dt
        return row


@njit_noalloc
def current_velocity(rows, r, current, t):
    """Interpolated current V_c(t) (m/s, NED) of packed row ``r``: returns (Vx, Vy, Vz).

    Linear interpolation on the uniform grid; the first/last sample is held outside it.
    """
    off, n, h = int(rows[r, C_OFFSET]), int(rows[r, C_N]), rows[r, C_DT]
    s = t / h
    if not s > 0.0:  # also catches NaN
        k = off
        return current[k, 1], current[k, 2], current[k, 3]
    if s >= n - 1:
        k = off + n - 1
        return current[k, 1], current[k, 2], current[k, 3]
    i = int(s)
    f = s - i
    k = off + i
    return (current[k, 1] + f * (current[k + 1, 1] - current[k, 1]),
            current[k, 2] + f * (current[k + 1, 2] - current[k, 2]),
            current[k, 3] + f * (current[k + 1, 3] - current[k, 3]))


@njit_noalloc
def add_current_force(vx, vy, vz, eta, vp, out):
    """Add omega[0:3] = diag(d11, d22, d33) J1(theta, psi)^T V_c (N) to ``out`` (5,).

    V_c = (vx, vy, vz) is the NED current (m/s); J1^T is :func:`~auvtrack.vehicle.kinematics.body_from_ned`.
    """
    uc, vc, wc = body_from_ned(attitude(eta[3], eta[4]), (vx, vy, vz))
    out[0] += vp[VP.d] * uc
    out[1] += vp[VP.d + 1] * vc
    out[2] += vp[VP.d + 2] * wc
