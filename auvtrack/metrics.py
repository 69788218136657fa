"""Tracking and control-effort metrics: a compiled accumulator and a NumPy reference.

The simulation engine calls :func:`metrics_update` once per integration step with the values at
the *left* end of the step (rectangle rule), and :func:`metrics_finalize` once at the end.
:func:`metrics_from_trajectory` computes the same quantities from sampled arrays; the two are
tested against each other.  Definitions, units and the window rule are in ``docs/metrics.md``.

Window rule: the step ``[t, t + dt)`` belongs to the window ``[t0, t1)`` when
``t0 - tol <= t < t1 - tol`` with ``tol = 1e-6 * dt`` (so float noise in ``k * dt`` never moves a
step in or out).  Total variation is measured on the fixed grid ``g_m = t0 + m * TV_GRID``:
tau is sampled at the first in-window step with ``t + tol >= g_m``.
"""
from __future__ import annotations

import math

import numpy as np

from .jit import njit, njit_noalloc

AXES = ("x", "y", "z")
INPUTS = ("u", "q", "r")
SETTLE_THRESHOLDS = (0.05, 0.01, 0.001)  # m
SETTLE_LABELS = ("5cm", "1cm", "1mm")
TV_GRID = 0.01  # s, total-variation sampling grid
TOL_FRACTION = 1e-6  # window / grid tolerance as a fraction of dt

# accumulator layout (float64 array of METRICS_SIZE)
OFF_E2, OFF_IAE, OFF_ITAE, OFF_EMAX = 0, 3, 6, 9
OFF_SETTLE = 12  # 9 values, index OFF_SETTLE + 3 * threshold + axis; NaN = never exceeded
OFF_ABOVE = 21  # 9 flags: was the latest in-window sample at or above the threshold
OFF_TMAX, OFF_TEN, OFF_TV, OFF_TPREV = 30, 33, 36, 39
OFF_DUR, OFF_NSTEP, OFF_GRID_K, OFF_HAVE_PREV = 42, 43, 44, 45
OFF_SAT = 46  # 3 values: seconds in the window with the command of input j saturated
METRICS_SIZE = 49

_AXIS_KINDS = ("rmse", "iae", "itae", "max_abs") + tuple(f"settle_{s}" for s in SETTLE_LABELS)
_INPUT_KINDS = ("max_abs_tau", "energy_tau", "tv_tau", "t_sat_tau")
METRIC_NAMES: tuple[str, ...] = tuple(f"{k}_{a}" for k in _AXIS_KINDS for a in AXES) + tuple(
    f"{k}_{j}" for k in _INPUT_KINDS for j in INPUTS)
"""Every metric name, in the order :func:`metrics_finalize` returns them."""

METRIC_UNITS: dict[str, str] = {
    "rmse": "m", "iae": "m*s", "itae": "m*s^2", "max_abs": "m", "settle": "s",
    "max_abs_tau": "N (u) or N*m (q, r)", "energy_tau": "N^2*s (u) or N^2*m^2*s (q, r)",
    "tv_tau": "N/s (u) or N*m/s (q, r)", "t_sat_tau": "s",
}
"""Units of each metric family (the name without its axis / input suffix)."""


@njit
def metrics_init(acc):
    """Reset a metrics accumulator.

    Parameters
    ----------
    acc : numpy.ndarray
        A float64 array of size :data:`METRICS_SIZE`, modified in place.
    """
    for i in range(METRICS_SIZE):
        acc[i] = 0.0
    for i in range(9):
        acc[OFF_SETTLE + i] = np.nan


@njit_noalloc(inline="always")
def metrics_update(acc, t, dt, e, tau, t0, t1):
    """Add one integration step (left-point values) to the accumulator; allocation-free.

    Parameters
    ----------
    acc : numpy.ndarray
        Accumulator initialised by :func:`metrics_init`, modified in place.
    t : float
        Time at the start of the step (s).
    dt : float
        Step length (s), > 0.
    e : numpy.ndarray
        Position error eta1 - eta_d at ``t``, shape (3,) (m).
    tau : numpy.ndarray
        Input [tau_u (N), tau_q (N m), tau_r (N m)] at ``t``, shape (3,).
    t0, t1 : float
        Metrics window; ``t1`` may be ``inf`` (or a huge number) for "end of run".
    """
    tol = TOL_FRACTION * dt
    if t < t0 - tol or t >= t1 - tol:
        return
    acc[OFF_DUR] += dt
    acc[OFF_NSTEP] += 1.0
    for i in range(3):
        a = abs(e[i])
        acc[OFF_E2 + i] += a * a * dt
        acc[OFF_IAE + i] += a * dt
        acc[OFF_ITAE + i] += t * a * dt
        if a > acc[OFF_EMAX + i]:
            acc[OFF_EMAX + i] = a
        for j in range(3):
            k = 3 * j + i
            if a >= SETTLE_THRESHOLDS[j]:
                acc[OFF_SETTLE + k] = t + dt
                acc[OFF_ABOVE + k] = 1.0
            else:
                acc[OFF_ABOVE + k] = 0.0
    for j in range(3):
        a = abs(tau[j])
        if a > acc[OFF_TMAX + j]:
            acc[OFF_TMAX + j] = a
        acc[OFF_TEN + j] += tau[j] * tau[j] * dt
    # total variation on the fixed grid g_m = t0 + m * TV_GRID
    s = t + tol
    k = acc[OFF_GRID_K]
    if s >= t0 + k * TV_GRID:
        for j in range(3):
            if acc[OFF_HAVE_PREV] > 0.0:
                acc[OFF_TV + j] += abs(tau[j] - acc[OFF_TPREV + j])
            acc[OFF_TPREV + j] = tau[j]
        acc[OFF_HAVE_PREV] = 1.0
        # next grid point strictly after s: start one below the estimate, then step up
        k = max(k, math.floor((s - t0) / TV_GRID) - 1.0)
        while t0 + k * TV_GRID <= s:
            k += 1.0
        acc[OFF_GRID_K] = k


@njit_noalloc(inline="always")
def saturation_update(acc, t, dt, flags, t0, t1):
    """Add one step to the saturation times: bit j of ``flags`` set means input j's command was saturated.

    Parameters
    ----------
    acc : numpy.ndarray
        Accumulator initialised by :func:`metrics_init`, modified in place.
    t, dt : float
        Start and length of the step (s).
    flags : int
        Bitmask returned by the plant's allocation for this step.
    t0, t1 : float
        Metrics window (same rule as :func:`metrics_update`).
    """
    tol = TOL_FRACTION * dt
    if flags == 0 or t < t0 - tol or t >= t1 - tol:
        return
    for j in range(3):
        if (flags >> j) & 1:
            acc[OFF_SAT + j] += dt


def _empty_metrics() -> dict[str, float]:
    return {name: math.nan for name in METRIC_NAMES}


def metrics_finalize(acc: np.ndarray, t0: float, t_end: float) -> dict[str, float]:
    """Turn an accumulator into the named metrics.

    Parameters
    ----------
    acc : numpy.ndarray
        Accumulator filled by :func:`metrics_update`.
    t0 : float
        Window start (s): the settling time reported when |e| never reached a threshold.
    t_end : float
        End of the window actually simulated, ``min(t1, t_stop)`` (s).  Only used to detect an
        empty window; means are normalised by the accumulated step lengths, which equal
        ``t_end - t0`` whenever the window bounds are multiples of dt.

    Returns
    -------
    dict of str to float
        Keys :data:`METRIC_NAMES`.  Settling times may be ``inf`` (above the threshold at the
        window end).  An empty window gives NaN everywhere.
    """
    acc = np.asarray(acc, dtype=float)
    dur = float(acc[OFF_DUR])
    if not (dur > 0.0) or acc[OFF_NSTEP] < 1 or not (t_end > t0):
        return _empty_metrics()
    out: dict[str, float] = {}
    for i, a in enumerate(AXES):
        out[f"rmse_{a}"] = math.sqrt(acc[OFF_E2 + i] / dur)
    for i, a in enumerate(AXES):
        out[f"iae_{a}"] = float(acc[OFF_IAE + i])
    for i, a in enumerate(AXES):
        out[f"itae_{a}"] = float(acc[OFF_ITAE + i])
    for i, a in enumerate(AXES):
        out[f"max_abs_{a}"] = float(acc[OFF_EMAX + i])
    for j, lab in enumerate(SETTLE_LABELS):
        for i, a in enumerate(AXES):
            k = 3 * j + i
            if acc[OFF_ABOVE + k] > 0.0:
                val = math.inf
            elif math.isnan(acc[OFF_SETTLE + k]):
                val = float(t0)
            else:
                val = float(acc[OFF_SETTLE + k])
            out[f"settle_{lab}_{a}"] = val
    for j, n in enumerate(INPUTS):
        out[f"max_abs_tau_{n}"] = float(acc[OFF_TMAX + j])
    for j, n in enumerate(INPUTS):
        out[f"energy_tau_{n}"] = float(acc[OFF_TEN + j])
    for j, n in enumerate(INPUTS):
        out[f"tv_tau_{n}"] = float(acc[OFF_TV + j]) / dur
    for j, n in enumerate(INPUTS):
        out[f"t_sat_tau_{n}"] = float(acc[OFF_SAT + j])
    return out


def metrics_from_trajectory(t, e, tau, t0: float = 0.0, t1: float = math.inf,
                            saturated=None) -> dict[str, float]:
    """Reference (pure NumPy) implementation of the metrics on sampled arrays.

    Sample k stands for the interval ``[t[k], t[k+1])`` (rectangle rule, left point); the last
    sample only closes the previous interval.  Same window and 10 ms grid rules as the compiled
    accumulator, so feeding that accumulator ``(t[k], t[k+1] - t[k], e[k], tau[k])`` for every
    k < N - 1 gives the same numbers up to summation order.

    Parameters
    ----------
    t : array_like
        Strictly increasing sample times, shape (N,) (s).
    e : array_like
        Position errors, shape (N, 3) (m).
    tau : array_like
        Inputs [tau_u, tau_q, tau_r], shape (N, 3).
    t0 : float, optional
        Window start (s).
    t1 : float, optional
        Window end (s); ``inf`` for the end of the samples.
    saturated : array_like of bool, optional
        Shape (N, 3): whether each input's command was saturated at each sample (default: never).

    Returns
    -------
    dict of str to float
        Keys :data:`METRIC_NAMES`; see :func:`metrics_finalize`.

    Raises
    ------
    ValueError
        On inconsistent shapes or non-increasing times.
    """
    t = np.asarray(t, dtype=float)
    e = np.asarray(e, dtype=float)
    tau = np.asarray(tau, dtype=float)
    if t.ndim != 1 or e.shape != (t.size, 3) or tau.shape != (t.size, 3):
        raise ValueError("expected t of shape (N,), e and tau of shape (N, 3)")
    if t.size < 2:
        return _empty_metrics()
    dt_all = np.diff(t)
    if np.any(~(dt_all > 0)):
        raise ValueError("t must be strictly increasing")
    tl, el, taul = t[:-1], e[:-1], tau[:-1]
    tol_all = TOL_FRACTION * dt_all
    win = (tl >= t0 - tol_all) & (tl < t1 - tol_all)
    if not np.any(win):
        return _empty_metrics()
    tw, dt, ew, tauw, tol = tl[win], dt_all[win], np.abs(el[win]), taul[win], tol_all[win]
    dur = float(np.sum(dt))
    out: dict[str, float] = {}
    for i, a in enumerate(AXES):
        out[f"rmse_{a}"] = math.sqrt(float(np.sum(ew[:, i] * ew[:, i] * dt)) / dur)
    for i, a in enumerate(AXES):
        out[f"iae_{a}"] = float(np.sum(ew[:, i] * dt))
    for i, a in enumerate(AXES):
        out[f"itae_{a}"] = float(np.sum(tw * ew[:, i] * dt))
    for i, a in enumerate(AXES):
        out[f"max_abs_{a}"] = float(np.max(ew[:, i]))
    for thr, lab in zip(SETTLE_THRESHOLDS, SETTLE_LABELS):
        for i, a in enumerate(AXES):
            above = np.flatnonzero(ew[:, i] >= thr)
            if above.size == 0:
                val = float(t0)
            elif above[-1] == ew.shape[0] - 1:
                val = math.inf
            else:
                val = float(tw[above[-1]] + dt[above[-1]])
            out[f"settle_{lab}_{a}"] = val
    for j, n in enumerate(INPUTS):
        out[f"max_abs_tau_{n}"] = float(np.max(np.abs(tauw[:, j])))
    for j, n in enumerate(INPUTS):
        out[f"energy_tau_{n}"] = float(np.sum(tauw[:, j] * tauw[:, j] * dt))
    idx = tv_sample_indices(tw, tol, t0)
    for j, n in enumerate(INPUTS):
        out[f"tv_tau_{n}"] = float(np.sum(np.abs(np.diff(tauw[idx, j])))) / dur
    sat = np.zeros((t.size, 3), bool) if saturated is None else np.asarray(saturated, bool)
    if sat.shape != (t.size, 3):
        raise ValueError("expected saturated of shape (N, 3)")
    for j, n in enumerate(INPUTS):
        out[f"t_sat_tau_{n}"] = float(np.sum(dt[sat[:-1][win][:, j]]))
    return out


def tv_sample_indices(t: np.ndarray, tol: np.ndarray, t0: float) -> np.ndarray:
    """Indices of the in-window samples used for the total variation (the 10 ms grid rule).

    Parameters
    ----------
    t : numpy.ndarray
        In-window step start times, increasing (s).
    tol : numpy.ndarray
        Per-step tolerance ``1e-6 * dt``.
    t0 : float
        Window start (s), the first grid point.

    Returns
    -------
    numpy.ndarray
        Sorted unique indices: for each grid point ``t0 + m * TV_GRID``, the first sample with
        ``t + tol >= t0 + m * TV_GRID``.
    """
    s = t + tol  # strictly increasing because tol < dt
    m_max = int(math.floor((s[-1] - t0) / TV_GRID)) + 2
    grid = t0 + np.arange(m_max + 1, dtype=float) * TV_GRID
    grid = grid[grid <= s[-1]]
    return np.unique(np.searchsorted(s, grid, side="left"))


__all__ = ["METRICS_SIZE", "METRIC_NAMES", "METRIC_UNITS", "AXES", "INPUTS", "SETTLE_THRESHOLDS",
           "TV_GRID", "metrics_init", "metrics_update", "saturation_update", "metrics_finalize", "metrics_from_trajectory",
           "tv_sample_indices"]
