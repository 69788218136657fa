"""Tracking, path-following and control-effort metrics: a compiled accumulator and a NumPy reference.

The simulation engine calls :func:`metrics_update`, :func:`saturation_update`, :func:`path_update`
and :func:`effort_update` once per integration step with the values at the *left* end of the step
(rectangle rule), and :func:`metrics_finalize` once at the end.
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
from .jit.lane_values import lane_at, lane_column, lane_count
from .reference.path import SPEED2_MIN, along_track_error, path_errors, project, project_from

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
# path following at the navigation point (path_update): previous path parameter, then per half
OFF_PATH_S = 49  # the path parameter of the previous step (NaN before the first step)
OFF_PATH = 50  # whole window: duration, sum y_e^2 dt, max |y_e|, sum z_e^2 dt, sum along^2 dt
OFF_PATH_LATE = 55  # the same over the second half of the window
PATH_DUR, PATH_XT2, PATH_XTMAX, PATH_VT2, PATH_AL2 = 0, 1, 2, 3, 4
# actuator use (effort_update): duration, then 3 values each
OFF_ACT_DUR = 60
OFF_ACT2, OFF_ACT_MAX, OFF_ACT_TV, OFF_ACT_PREV, OFF_ACT_LIMIT = 61, 64, 67, 70, 73
OFF_ACT_GRID_K, OFF_ACT_HAVE_PREV = 76, 77
OFF_PATH_PT = 78  # 9 values: the path point at OFF_PATH_S (position, velocity, acceleration), the next warm start
METRICS_SIZE = 87
PATH_WINDOW = 10.0  # s of path time: half-width of the projection's search window per step
LIMIT_TOL = 1e-9  # an actuator is at its limit when its fraction of the limit is >= 1 - LIMIT_TOL

_AXIS_KINDS = ("rmse", "iae", "itae", "max_abs") + tuple(f"settle_{s}" for s in SETTLE_LABELS)
_INPUT_KINDS = ("max_abs_tau", "energy_tau", "tv_tau", "t_sat_tau")
PATH_NAMES = ("xtrack_rmse", "xtrack_max", "vtrack_rmse", "along_rmse")
"""Path-following metrics at the navigation point; each also with the suffix ``_late`` (second half)."""
_ACTUATOR_KINDS = ("act_rms", "act_max", "act_rate", "t_act_limit")
METRIC_NAMES: tuple[str, ...] = tuple(f"{k}_{a}" for k in _AXIS_KINDS for a in AXES) + tuple(
    f"{k}_{j}" for k in _INPUT_KINDS for j in INPUTS) + PATH_NAMES + tuple(
    f"{k}_late" for k in PATH_NAMES) + tuple(f"{k}_{j}" for k in _ACTUATOR_KINDS for j in INPUTS)
"""Every metric name, in the order :func:`metrics_finalize` returns them."""

METRIC_UNITS: dict[str, str] = {
    "rmse": "m", "iae": "m*s", "itae": "m*s^2", "max_abs": "m", "settle": "s",
    "max_abs_tau": "N (u) or N*m (q, r)", "energy_tau": "N^2*s (u) or N^2*m^2*s (q, r)",
    "tv_tau": "N/s (u) or N*m/s (q, r)", "t_sat_tau": "s",
    "xtrack_rmse": "m", "xtrack_max": "m", "vtrack_rmse": "m", "along_rmse": "m",
    "act_rms": "fraction of the limit", "act_max": "fraction of the limit",
    "act_rate": "fraction of the limit per s", "t_act_limit": "s",
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
    acc[OFF_PATH_S] = np.nan


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
    grid_tv_update(acc, OFF_GRID_K, OFF_HAVE_PREV, OFF_TPREV, OFF_TV, tau, t + tol, t0)


@njit_noalloc(inline="always")
def grid_tv_update(acc, off_k, off_have, off_prev, off_tv, x, s, t0):
    """Total variation of three signals on the fixed grid g_m = t0 + m * TV_GRID (the 10 ms rule).

    Parameters
    ----------
    acc : numpy.ndarray
        Accumulator, modified in place: the next grid index at ``off_k``, a "have a previous
        sample" flag at ``off_have``, the previous samples at ``off_prev`` and the sums at ``off_tv``.
    off_k, off_have, off_prev, off_tv : int
        Offsets in ``acc``.
    x : tuple or numpy.ndarray
        The three signals at this step.
    s : float
        Step start time plus the window tolerance (s).
    t0 : float
        Window start (s), the first grid point.
    """
    k = acc[off_k]
    if s >= t0 + k * TV_GRID:
        for j in range(3):
            if acc[off_have] > 0.0:
                acc[off_tv + j] += abs(x[j] - acc[off_prev + j])
            acc[off_prev + j] = x[j]
        acc[off_have] = 1.0
        # next grid point strictly after s: start one below the estimate, then step up
        k = max(k, math.floor((s - t0) / TV_GRID) - 1.0)
        while t0 + k * TV_GRID <= s:
            k += 1.0
        acc[off_k] = k


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


@njit_noalloc(inline="always")
def _path_add(acc, off, dt, y_e, z_e, along):
    acc[off + PATH_DUR] += dt
    acc[off + PATH_XT2] += y_e * y_e * dt
    if abs(y_e) > acc[off + PATH_XTMAX]:
        acc[off + PATH_XTMAX] = abs(y_e)
    acc[off + PATH_VT2] += z_e * z_e * dt
    acc[off + PATH_AL2] += along * along * dt


@njit_noalloc(inline="always")
def path_update(acc, t, dt, p, path, t0, t1, t_late):
    """Project the navigation point on the path and add the step to the path-following sums.

    The projection (:func:`auvtrack.reference.path.project`) runs at every step up to the end of
    the window, before it too, from the previous step's path parameter (the time ``t`` at the first
    step), within :data:`PATH_WINDOW` of it, starting from the path point the previous step found
    there (kept in the accumulator: the same numbers as evaluating it again, one evaluation fewer);
    the cross-track, vertical-track and along-track errors are then accumulated over the window
    ``[t0, t1)`` and over its second half ``t >= t_late``.  Each projection is warm-started from the
    previous one, so the steps before ``t0`` are projected for the answers inside the window to be
    those of the chain from the first step; a step at or after ``t1`` is not projected at all: its
    answer would only warm-start later steps, which are outside the window too.

    Parameters
    ----------
    acc : numpy.ndarray
        Accumulator initialised by :func:`metrics_init`, modified in place.
    t, dt : float
        Start and length of the step (s).
    p : tuple of 3 float
        The vehicle's navigation point (its origin: x, y, z, m NED) at ``t``.
    path : numpy.ndarray
        The packed reference (:mod:`auvtrack.reference.kernel`).
    t0, t1 : float
        Metrics window (same rule as :func:`metrics_update`).
    t_late : float
        Start of the window's second half (s).
    """
    tol = TOL_FRACTION * dt
    if t >= t1 - tol:  # after the window (the rule of metrics_update): nothing to add or to warm-start
        return
    guess = acc[OFF_PATH_S]
    if math.isnan(guess):
        s, pt = project(path, t, p, PATH_WINDOW)
    else:
        o = OFF_PATH_PT
        s, pt = project_from(path, guess, ((acc[o], acc[o + 1], acc[o + 2]), (acc[o + 3], acc[o + 4], acc[o + 5]),
                                           (acc[o + 6], acc[o + 7], acc[o + 8])), p, PATH_WINDOW)
    acc[OFF_PATH_S] = s
    for i in range(3):
        for j in range(3):
            acc[OFF_PATH_PT + 3 * i + j] = pt[i][j]
    if t < t0 - tol:
        return
    e = path_errors(pt, p)
    along = along_track_error(pt, s, t)
    _path_add(acc, OFF_PATH, dt, e[1], e[2], along)
    if t >= t_late - tol:
        _path_add(acc, OFF_PATH_LATE, dt, e[1], e[2], along)


@njit_noalloc(inline="always")
def path_update_lanes(acc, t, dt, p, path, t0, t1, t_late, m):
    """Lane form of :func:`path_update` (SIMD batch): the scalar function once per lane of the mask ``m``.

    The projection's search takes a different number of path evaluations in each run (one per step
    near the path; up to a few dozen where the distance is flat in s, :mod:`auvtrack.reference.path`).
    Its rewritten lane form (:mod:`auvtrack.engine.lanes`) would run every loop for as long as its
    slowest lane, with the mask bookkeeping of every lane at each pass; called once per lane, each run
    takes only its own steps.  Each lane's values are the scalar function's, bit for bit (it is that
    function, on that lane's column of ``acc`` and ``path``).

    Parameters
    ----------
    acc : array of Lanes
        The accumulators (one per lane), modified in place.
    t, dt, t0, t1, t_late : float or Lanes
        As :func:`path_update`, per lane or shared.
    p : tuple of 3 float or Lanes
        The navigation point of each lane.
    path : array of Lanes
        Each lane's packed reference.
    m : Lanes of bool
        The lanes to update.
    """
    for k in range(lane_count(m)):
        if lane_at(m, k):
            path_update(lane_column(acc, k), lane_at(t, k), lane_at(dt, k),
                        (lane_at(p[0], k), lane_at(p[1], k), lane_at(p[2], k)), lane_column(path, k),
                        lane_at(t0, k), lane_at(t1, k), lane_at(t_late, k))


path_update.lane_form = path_update_lanes

@njit_noalloc(inline="always")
def effort_update(acc, t, dt, f, t0, t1):
    """Add one step of actuator use: each axis's actuator position as a fraction of its limit.

    Parameters
    ----------
    acc : numpy.ndarray
        Accumulator initialised by :func:`metrics_init`, modified in place.
    t, dt : float
        Start and length of the step (s).
    f : tuple of 3 float
        |position| / limit of the actuator of each axis (u, q, r) at ``t``, the plant's ``effort``
        (0 without a limit).
    t0, t1 : float
        Metrics window (same rule as :func:`metrics_update`).
    """
    tol = TOL_FRACTION * dt
    if t < t0 - tol or t >= t1 - tol:
        return
    acc[OFF_ACT_DUR] += dt
    for j in range(3):
        a = f[j]
        acc[OFF_ACT2 + j] += a * a * dt
        if a > acc[OFF_ACT_MAX + j]:
            acc[OFF_ACT_MAX + j] = a
        if a >= 1.0 - LIMIT_TOL:
            acc[OFF_ACT_LIMIT + j] += dt
    grid_tv_update(acc, OFF_ACT_GRID_K, OFF_ACT_HAVE_PREV, OFF_ACT_PREV, OFF_ACT_TV, f, t + tol, t0)


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
    for off, suffix in ((OFF_PATH, ""), (OFF_PATH_LATE, "_late")):
        out.update(_path_metrics(acc[off + PATH_DUR], acc[off + PATH_XT2], acc[off + PATH_XTMAX],
                                 acc[off + PATH_VT2], acc[off + PATH_AL2], suffix))
    out.update(_actuator_metrics(acc[OFF_ACT_DUR], acc[OFF_ACT2:OFF_ACT2 + 3], acc[OFF_ACT_MAX:OFF_ACT_MAX + 3],
                                 acc[OFF_ACT_TV:OFF_ACT_TV + 3], acc[OFF_ACT_LIMIT:OFF_ACT_LIMIT + 3]))
    return out


def _path_metrics(dur, xt2, xtmax, vt2, al2, suffix: str) -> dict[str, float]:
    """The four path-following metrics of one half from their sums (NaN for an empty half)."""
    if not dur > 0.0:
        return {f"{k}{suffix}": math.nan for k in PATH_NAMES}
    return {f"xtrack_rmse{suffix}": math.sqrt(xt2 / dur), f"xtrack_max{suffix}": float(xtmax),
            f"vtrack_rmse{suffix}": math.sqrt(vt2 / dur), f"along_rmse{suffix}": math.sqrt(al2 / dur)}


def _actuator_metrics(dur, sq, peak, tv, at_limit) -> dict[str, float]:
    """The actuator-use metrics from their sums (NaN when no step was added)."""
    out: dict[str, float] = {}
    for k in _ACTUATOR_KINDS:
        for j, n in enumerate(INPUTS):
            if not dur > 0.0:
                out[f"{k}_{n}"] = math.nan
            elif k == "act_rms":
                out[f"{k}_{n}"] = math.sqrt(sq[j] / dur)
            elif k == "act_max":
                out[f"{k}_{n}"] = float(peak[j])
            elif k == "act_rate":
                out[f"{k}_{n}"] = float(tv[j]) / dur
            else:
                out[f"{k}_{n}"] = float(at_limit[j])
    return out


def metrics_from_trajectory(t, e, tau, t0: float = 0.0, t1: float = math.inf,
                            saturated=None, *, position=None, path=None, effort=None,
                            t_late: float | None = None) -> dict[str, float]:
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
    position : array_like, optional
        Shape (N, 3): the navigation point (the vehicle's origin, m NED); with ``path``, the
        path-following metrics (NaN without them).
    path : numpy.ndarray or auvtrack.reference.Reference, optional
        The reference (packed, or a reference object).
    effort : array_like, optional
        Shape (N, 3): each axis's actuator position as a fraction of its limit (the plant's
        ``effort``); the actuator-use metrics (NaN without it).
    t_late : float, optional
        Start of the window's second half (s); default the middle of ``[t0, min(t1, t[-1])]``.

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
    if t_late is None:
        t_late = 0.5 * (t0 + min(t1, float(t[-1])))
    late = tw >= t_late - tol
    errors = None if position is None or path is None else path_errors_of_samples(path, t, position)
    for mask, suffix in ((np.ones(tw.size, bool), ""), (late, "_late")):
        if errors is None:
            out.update({f"{k}{suffix}": math.nan for k in PATH_NAMES})
            continue
        y_e, z_e, along = (x[:-1][win][mask] for x in errors)
        d = dt[mask]
        out.update(_path_metrics(np.sum(d), np.sum(y_e * y_e * d), np.max(np.abs(y_e), initial=0.0),
                                 np.sum(z_e * z_e * d), np.sum(along * along * d), suffix))
    if effort is None:
        out.update(_actuator_metrics(0.0, None, None, None, None))
    else:
        f = np.asarray(effort, dtype=float)
        if f.shape != (t.size, 3):
            raise ValueError("expected effort of shape (N, 3)")
        fw = f[:-1][win]
        out.update(_actuator_metrics(dur, np.sum(fw * fw * dt[:, None], axis=0), np.max(fw, axis=0),
                                     np.sum(np.abs(np.diff(fw[idx], axis=0)), axis=0),
                                     np.sum(dt[:, None] * (fw >= 1.0 - LIMIT_TOL), axis=0)))
    return out


def path_errors_of_samples(path, t, position, window: float = PATH_WINDOW) -> tuple[np.ndarray, ...]:
    """Cross-track, vertical-track and along-track errors of sampled positions (NumPy reference).

    Each sample is projected on the path near the previous sample's path parameter (the first
    near its time), as the compiled :func:`path_update` does at every step: on a grid of 401
    points of the window ``[s_prev - window, s_prev + window]`` the distance is followed downhill
    from ``s_prev`` to a local minimum, which is then refined by Brent's bounded minimisation
    between its grid neighbours and polished by Brent's root finding on
    (eta_d(s) - p) . eta_d'(s) = 0.  Where the path stands still it is no part of the path (as in
    the compiled projection); a start there stays there.  The errors are
    ``R_y(pi_v)^T R_z(pi_h)^T (p - eta_d(s))`` (Fossen & Aguiar 2024; MSS ``ALOS3D``) with explicit
    rotation matrices, and (s - t) |eta_d'(s)|.

    Parameters
    ----------
    path : numpy.ndarray or auvtrack.reference.Reference
        The reference.
    t : array_like
        Sample times, shape (N,) (s).
    position : array_like
        Shape (N, 3): positions (m, NED).
    window : float, optional
        Half-width of the search window (s of path time).

    Returns
    -------
    (numpy.ndarray, numpy.ndarray, numpy.ndarray)
        y_e, z_e and the along-track timing error (m), shape (N,) each; where the path stands
        still, y_e is the horizontal distance and z_e the depth difference.
    """
    from .reference import eval_reference_batch

    packed = np.ascontiguousarray(path.pack() if hasattr(path, "pack") else path, dtype=float)
    t = np.asarray(t, dtype=float)
    P = np.asarray(position, dtype=float)
    if P.shape != (t.size, 3):
        raise ValueError("expected position of shape (N, 3)")

    def at(s):
        out = np.empty((np.size(s), 3, 3))
        eval_reference_batch(packed, np.ascontiguousarray(np.atleast_1d(s), dtype=float), out)
        return out

    offsets = np.linspace(-window, window, 401)
    s_all = np.empty(t.size)
    s_prev = t[0] if t.size else 0.0
    for k in range(t.size):
        s_prev = s_all[k] = _closest_near(at, P[k], s_prev, offsets)
    pts = at(s_all)
    pos, vel = pts[:, 0], pts[:, 1]
    d = P - pos
    vh = np.hypot(vel[:, 0], vel[:, 1])
    speed = np.sqrt(vh * vh + vel[:, 2] ** 2)
    pi_h, pi_v = np.arctan2(vel[:, 1], vel[:, 0]), np.arctan2(-vel[:, 2], vh)
    ch, sh, cv, sv = np.cos(pi_h), np.sin(pi_h), np.cos(pi_v), np.sin(pi_v)
    zero, one = np.zeros_like(ch), np.ones_like(ch)
    Rz = np.stack([np.stack([ch, -sh, zero], -1), np.stack([sh, ch, zero], -1), np.stack([zero, zero, one], -1)], -2)
    Ry = np.stack([np.stack([cv, zero, sv], -1), np.stack([zero, one, zero], -1), np.stack([-sv, zero, cv], -1)], -2)
    e = np.einsum("nji,nkj,nk->ni", Ry, Rz, d)  # R_y^T R_z^T d
    still = ~(speed * speed > SPEED2_MIN)
    e[still, 1] = np.hypot(d[still, 0], d[still, 1])
    e[still, 2] = d[still, 2]
    return e[:, 1], e[:, 2], (s_all - t) * speed


def _closest_near(at, p, s_prev, offsets) -> float:
    """The projection of :func:`path_errors_of_samples` of one position ``p`` from ``s_prev``."""
    from scipy.optimize import brentq, minimize_scalar

    def slope(s):
        pt = at(s)[0]
        return float(np.dot(pt[0] - p, pt[1]))

    def dist2(s):
        return float(np.sum((at(s)[0, 0] - p) ** 2))

    def moving(s):
        v = at(s)[0, 1]
        return bool(v @ v > SPEED2_MIN)

    def edge(inside, outside):  # the end of the moving part between a moving and a standing parameter
        for _ in range(60):
            mid = 0.5 * (inside + outside)
            inside, outside = (mid, outside) if moving(mid) else (inside, mid)
        return inside

    grid = s_prev + offsets
    pts = at(grid)
    # a standing part of the path is no part of it (as in the compiled projection)
    dist = np.where(np.sum(pts[:, 1] ** 2, axis=1) > SPEED2_MIN, np.sum((pts[:, 0] - p) ** 2, axis=1), math.inf)
    i = offsets.size // 2
    if not math.isfinite(dist[i]):
        return s_prev
    step = 1 if dist[i + 1] < dist[i] else (-1 if dist[i - 1] < dist[i] else 0)
    while step and 0 <= i + step < offsets.size and dist[i + step] < dist[i]:
        i += step
    a, b = grid[max(i - 1, 0)], grid[min(i + 1, offsets.size - 1)]
    a = a if moving(a) else edge(grid[i], a)
    b = b if moving(b) else edge(grid[i], b)
    s = minimize_scalar(dist2, bounds=(a, b), method="bounded", options={"xatol": 1e-12}).x
    h = 1e-6 * (b - a)
    if a < s - h and s + h < b and slope(s - h) < 0.0 < slope(s + h):
        s = brentq(slope, s - h, s + h, xtol=1e-14, rtol=4 * np.finfo(float).eps)
    return float(s)


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


__all__ = ["METRICS_SIZE", "METRIC_NAMES", "METRIC_UNITS", "AXES", "INPUTS", "SETTLE_THRESHOLDS", "PATH_NAMES",
           "TV_GRID", "PATH_WINDOW", "LIMIT_TOL", "metrics_init", "metrics_update", "saturation_update", "path_update",
           "effort_update", "grid_tv_update", "metrics_finalize", "metrics_from_trajectory", "path_errors_of_samples",
           "tv_sample_indices"]
