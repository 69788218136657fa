"""Packing disturbance components into arrays, and the compiled evaluator of omega(t).

:func:`pack_disturbances` turns a list of components into a :class:`DisturbanceTables` (layout in
:mod:`auvtrack.environment.layout`); :func:`eval_disturbance` is the compiled, allocation-free
evaluator the simulation engine calls at every RK4 stage.  The array types never change (2-D
``float64`` C-contiguous ``rows`` and ``current``; an empty list gives a ``(0, 8)`` rows array
and a ``(1, 4)`` zero current table), so one compiled specialisation serves every combination.

Seeding: the i-th :class:`GaussMarkovCurrent` of the list (counting currents only, from 0)
draws its samples from ``rng(seed, f"current/{i}")``; adding or removing a deterministic
component therefore never changes a current's samples.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..jit import njit, njit_noalloc
from .._seeding import rng
from ..vehicle.params import VP
from .current import add_current_force
from .dispatch import add_forces, current_of
from .layout import C_N, C_OFFSET, CUR_COLS, KIND_CURRENT, ROW_SIZE
from .registry import COMPONENTS


@njit_noalloc(inline="always")
def eval_disturbance(rows, current, t, eta, nu, vp, out):
    """Write the total disturbance omega(t) (5,) into ``out``: N (surge, sway, heave), N m (q, r).

    Parameters
    ----------
    rows : ndarray, shape (n, 8)
        Packed components.
    current : ndarray, shape (m, 4)
        Stacked current samples (t, Vx, Vy, Vz).
    t : float
        Time, s.
    eta, nu : ndarray, shape (5,)
        Pose (the current force depends on pitch and yaw) and body velocity (unused by the
        present models, kept for the interface).
    vp : ndarray
        Packed vehicle whose damping maps the current to a force (the true plant's).
    out : ndarray, shape (5,)
        Output.  A row with an unknown kind code makes every entry NaN.
    """
    for i in range(5):
        out[i] = 0.0
    vx = vy = vz = 0.0
    have_current = bad = False
    for k in range(rows.shape[0]):
        if add_forces(rows, k, t, out):
            continue
        hit, v = current_of(rows, k, current, t)
        if hit:
            vx += v[0]
            vy += v[1]
            vz += v[2]
            have_current = True
        else:
            bad = True
    if have_current:  # the force is linear in V_c: map the summed current once
        add_current_force(vx, vy, vz, eta, vp, out)
    if bad:
        for i in range(5):
            out[i] = math.nan


@njit
def eval_current_velocity(rows, current, t, out):
    """Write the summed current velocity V_c(t) (3,), m/s NED, of all current rows into ``out``."""
    out[0] = out[1] = out[2] = 0.0
    for k in range(rows.shape[0]):
        hit, v = current_of(rows, k, current, t)
        if hit:
            out[0] += v[0]
            out[1] += v[1]
            out[2] += v[2]


@njit
def _eval_series(rows, current, ts, eta, nu, vp, out):
    for i in range(ts.shape[0]):
        eval_disturbance(rows, current, ts[i], eta, nu, vp, out[i])


def _vec(x, n: int, name: str) -> np.ndarray:
    a = np.zeros(n) if x is None else np.ascontiguousarray(x, dtype=np.float64)
    if a.shape != (n,):
        raise ValueError(f"{name} must have shape ({n},), got {a.shape}")
    return a


@dataclass(frozen=True)
class DisturbanceTables:
    """Packed disturbances ready for compiled code.

    Attributes
    ----------
    rows : ndarray, shape (n_components, 8)
        One packed row per component (layout in :mod:`auvtrack.environment.layout`).
    current : ndarray, shape (n_samples_total, 4)
        Stacked Gauss-Markov samples (t, Vx, Vy, Vz); a (1, 4) zero row when there is no current.
    components : tuple
        The components, in order.
    duration, seed
        What the tables were generated for.
    """

    rows: np.ndarray
    current: np.ndarray
    components: tuple
    duration: float
    seed: int

    @property
    def has_current(self) -> bool:
        """Whether any component is a current (the evaluator then needs ``vp``)."""
        return any(c.EFFECT == "current" for c in self.components)

    def evaluate(self, t, eta=None, nu=None, vp=None) -> np.ndarray:
        """Evaluate omega with the compiled evaluator (for tests and plots).

        Parameters
        ----------
        t : float or array_like
            Time(s), s.
        eta, nu : array_like, shape (5,), optional
            Pose and body velocity (default zeros), held fixed for every ``t``.
        vp : array_like, optional
            Packed vehicle; required when a current is present (its damping maps V_c to force).

        Returns
        -------
        ndarray
            Shape (5,) for scalar ``t``, (len(t), 5) otherwise.
        """
        if vp is None:
            if self.has_current:
                raise ValueError("vp (packed vehicle) is required to evaluate a current's force")
            vp = np.zeros(VP.size)
        vp = np.ascontiguousarray(vp, dtype=np.float64)
        eta, nu = _vec(eta, 5, "eta"), _vec(nu, 5, "nu")
        ts = np.asarray(t, dtype=np.float64)
        if ts.ndim == 0:
            out = np.zeros(5)
            eval_disturbance(self.rows, self.current, float(ts), eta, nu, vp, out)
            return out
        ts = np.ascontiguousarray(ts.ravel())
        out = np.zeros((ts.size, 5))
        _eval_series(self.rows, self.current, ts, eta, nu, vp, out)
        return out

    def current_velocity(self, t: float) -> np.ndarray:
        """Summed current velocity V_c(t) (3,), m/s NED (zeros without a current)."""
        out = np.zeros(3)
        eval_current_velocity(self.rows, self.current, float(t), out)
        return out

    def current_samples(self, index: int = 0) -> np.ndarray:
        """Samples (n, 4) = (t, Vx, Vy, Vz) of the ``index``-th current component (a view)."""
        rows = [r for r in self.rows if r[0] == KIND_CURRENT]
        if not 0 <= index < len(rows):
            raise IndexError(f"current index {index} out of range; there are {len(rows)} currents")
        off, n = int(rows[index][C_OFFSET]), int(rows[index][C_N])
        return self.current[off:off + n]

    def describe(self) -> dict:
        """JSON-serialisable record: components, duration, seed and each current's seed stream."""
        comps, i = [], 0
        for c in self.components:
            d = c.describe()
            if c.EFFECT == "current":
                d = {**d, "stream": f"current/{i}"}
                i += 1
            comps.append(d)
        return {"seed": self.seed, "duration": self.duration, "components": comps}


def pack_disturbances(components: list, duration: float, seed: int) -> DisturbanceTables:
    """Pack components into :class:`DisturbanceTables`, generating every current's samples.

    Parameters
    ----------
    components : list
        :class:`PaperDisturbance`, :class:`Pulse` and :class:`GaussMarkovCurrent` instances; their
        effects add up.  An empty list gives omega = 0.
    duration : float
        Simulated time span, s, finite and >= 0; currents are sampled over ``[0, duration]``
        (and held beyond).
    seed : int
        Scenario seed; the i-th current uses ``rng(seed, f"current/{i}")``.

    Returns
    -------
    DisturbanceTables
    """
    if isinstance(duration, bool) or not isinstance(duration, (int, float, np.number)) \
            or not math.isfinite(duration) or duration < 0:
        raise ValueError(f"duration must be a finite real number >= 0 (s), got {duration!r}")
    rows, tables, offset, i_cur = [], [], 0, 0
    for c in components:
        if not isinstance(c, COMPONENTS):
            raise ValueError(f"disturbance component must be one of "
                             f"{[t.__name__ for t in COMPONENTS]}, got {type(c).__name__}")
        if c.EFFECT == "current":
            samples = c.sample(float(duration), rng(seed, f"current/{i_cur}"))
            rows.append(c.pack_row(offset, samples.shape[0]))
            tables.append(samples)
            offset += samples.shape[0]
            i_cur += 1
        else:
            rows.append(c.pack_row())
    row_arr = np.ascontiguousarray(np.array(rows, dtype=np.float64).reshape(len(rows), ROW_SIZE))
    cur = np.ascontiguousarray(np.vstack(tables)) if tables else np.zeros((1, CUR_COLS))
    return DisturbanceTables(row_arr, cur, tuple(components), float(duration), int(seed))
