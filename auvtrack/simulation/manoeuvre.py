"""The manoeuvre an open-loop run flew: turning-circle or zig-zag figures from its logged channels.

A controller that does not track a reference (``TRACKS = False``: ``open_loop``,
``open_loop_actuators``) flies a manoeuvre, so its tracking error means nothing; its result
carries these figures instead (``Result.meta["manoeuvre"]``, ``run.json``, the summary line).
The same definitions serve the manoeuvres study (:mod:`auvtrack.studies.manoeuvres`).

Definitions (ITTC Recommended Procedures 7.5-04-02-01, Full Scale Manoeuvring Trials; Fossen
2021, Section 16.x on manoeuvring trials), measured from the execute time t0 (heading psi0,
position p0, unit heading vector h = (cos psi0, sin psi0), normal n = (-sin psi0, cos psi0)):

* *advance*: distance along h travelled when the heading has changed by 90 deg;
* *transfer*: distance along the turn's normal at 90 deg (positive towards the turn);
* *tactical diameter*: distance along the normal at 180 deg;
* *steady turning diameter*: 2 U / |r| averaged over the last turn recorded (after 360 deg);
* zig-zag psi_s / delta: the rudder is put over to +delta, reversed each time the heading
  change reaches +-psi_s; *overshoot* = largest heading change beyond psi_s after each reversal
  (first, second), *initial turning time* = time to the first reversal, *period* = time between
  the first and the third reversal.

The functions take logged arrays (t in s, positions in m, angles in rad) and return dicts of plain
floats (NaN where the record is too short).
"""
from __future__ import annotations

import math

import numpy as np

__all__ = ["turning_circle_metrics", "zigzag_metrics", "manoeuvre_metrics", "manoeuvre_line"]


def _crossing(t: np.ndarray, y: np.ndarray, level: float) -> float:
    """First time y(t) reaches ``level`` (linear interpolation), NaN if never."""
    idx = np.nonzero(y >= level)[0]
    if idx.size == 0:
        return math.nan
    i = int(idx[0])
    if i == 0:
        return float(t[0])
    return float(t[i - 1] + (level - y[i - 1]) * (t[i] - t[i - 1]) / (y[i] - y[i - 1]))


def turning_circle_metrics(t, x, y, psi, u, v, r, t0: float = 0.0) -> dict:
    """Advance, transfer, tactical and steady turning diameter of a turning circle.

    Parameters
    ----------
    t, x, y, psi, u, v, r : array_like
        Time (s), NED position (m), heading (rad), surge and sway (m/s), yaw rate (rad/s).
    t0 : float
        Execute time (rudder put over), s.

    Returns
    -------
    dict
        ``advance``, ``transfer``, ``tactical_diameter``, ``steady_diameter`` (m),
        ``time_90``, ``time_180`` (s), ``turn_direction`` (+1 starboard, -1 port).
    """
    t, x, y, psi, u, v, r = (np.asarray(a, float) for a in (t, x, y, psi, u, v, r))
    k = t >= t0
    t, x, y, psi, u, v, r = t[k], x[k], y[k], psi[k], u[k], v[k], r[k]
    dpsi = np.unwrap(psi) - psi[0]
    side = 1.0 if dpsi[-1] >= 0 else -1.0
    turned = side * dpsi
    h = np.array([math.cos(psi[0]), math.sin(psi[0])])
    n = side * np.array([-math.sin(psi[0]), math.cos(psi[0])])
    dp = np.stack([x - x[0], y - y[0]], axis=1)
    along, across = dp @ h, dp @ n
    t90, t180 = _crossing(t, turned, math.pi / 2), _crossing(t, turned, math.pi)

    def at(tc, s):
        return float(np.interp(tc, t, s)) if math.isfinite(tc) else math.nan
    t360 = _crossing(t, turned, 2 * math.pi)
    if math.isfinite(t360):
        last = t >= t360
        speed = np.hypot(u[last], v[last])
        steady = float(np.mean(2.0 * speed / np.abs(r[last])))
    else:
        steady = math.nan
    return {"advance": at(t90, along), "transfer": at(t90, across), "tactical_diameter": at(t180, across),
            "steady_diameter": steady, "time_90": t90, "time_180": t180, "turn_direction": side}


def zigzag_metrics(t, psi, delta_r, psi_switch: float, t0: float = 0.0) -> dict:
    """Overshoots, initial turning time and period of a zig-zag manoeuvre.

    Parameters
    ----------
    t, psi, delta_r : array_like
        Time (s), heading (rad), applied rudder angle (rad).
    psi_switch : float
        Heading change at which the rudder is reversed, rad (> 0).
    t0 : float
        Execute time, s.

    Returns
    -------
    dict
        ``initial_turning_time``, ``period`` (s), ``overshoot_1``, ``overshoot_2`` (rad), and
        ``reversals`` (number of rudder reversals in the record).
    """
    t, psi, delta_r = (np.asarray(a, float) for a in (t, psi, delta_r))
    k = t >= t0
    t, dpsi = t[k], np.unwrap(psi[k]) - psi[k][0]
    # reversal times: the heading change crosses +-psi_switch alternately (first towards the turn)
    turn = np.sign(np.mean(dpsi[: max(2, len(dpsi) // 20)])) or 1.0
    times, sign, start = [], turn, 0
    while True:
        seg = sign * dpsi[start:]
        tc = _crossing(t[start:], seg, psi_switch)
        if not math.isfinite(tc):
            break
        times.append(tc)
        start = int(np.searchsorted(t, tc)) + 1
        sign = -sign
        if start >= len(t):
            break
    over = []
    for j, tc in enumerate(times[:2]):
        s = turn if j % 2 == 0 else -turn
        end = times[j + 1] if j + 1 < len(times) else t[-1]
        m = (t >= tc) & (t <= end)
        over.append(float(np.max(s * dpsi[m]) - psi_switch) if np.any(m) else math.nan)
    over += [math.nan] * (2 - len(over))
    return {"initial_turning_time": float(times[0] - t[0]) if times else math.nan,
            "period": float(times[2] - times[0]) if len(times) >= 3 else math.nan,
            "overshoot_1": over[0], "overshoot_2": over[1], "reversals": len(times)}


def manoeuvre_metrics(res, controller) -> dict | None:
    """Manoeuvre metrics of an open-loop run (ITTC 7.5-04-02-01; Fossen 2021, manoeuvring trials).

    A zig-zag (``controller.zigzag_psi > 0``) gives its overshoots, initial turning time and period;
    any other open-loop run that turns at least 90 deg after ``controller.t_execute`` gives advance,
    transfer, tactical and steady turning diameter (:mod:`auvtrack.studies.manoeuvres`).

    Parameters
    ----------
    res : Result
        The run.
    controller : pydantic model
        The scenario's ``[controller]`` section (an open-loop one).

    Returns
    -------
    dict or None
        ``{"manoeuvre": "zigzag" | "turning_circle", ...metrics (m, s, deg)}``, or None when the run
        holds no manoeuvre (no 90 deg turn, or too short).
    """
    import math

    import numpy as np

    t0 = float(getattr(controller, "t_execute", 0.0))
    psi_s = float(getattr(controller, "zigzag_psi", 0.0))
    if len(res) < 3:
        return None
    if psi_s > 0.0:
        rudder = res["delta_r"] if "delta_r" in res else np.zeros(len(res))
        m = zigzag_metrics(res.t, res["psi"], rudder, psi_s, t0)
        if m["reversals"] == 0:
            return None
        return {"manoeuvre": "zigzag", "zigzag_psi_deg": math.degrees(psi_s),
                "overshoot_1_deg": math.degrees(m["overshoot_1"]), "overshoot_2_deg": math.degrees(m["overshoot_2"]),
                "initial_turning_time_s": m["initial_turning_time"], "period_s": m["period"],
                "reversals": m["reversals"]}
    m = turning_circle_metrics(res.t, res["x"], res["y"], res["psi"], res["u"], res["v"], res["r"], t0)
    if not math.isfinite(m["time_90"]):
        return None
    return {"manoeuvre": "turning_circle", "advance_m": m["advance"], "transfer_m": m["transfer"],
            "tactical_diameter_m": m["tactical_diameter"], "steady_diameter_m": m["steady_diameter"],
            "turn": "starboard" if m["turn_direction"] > 0 else "port"}


def manoeuvre_line(metrics: dict) -> str:
    """One plain line of :func:`manoeuvre_metrics` (NaN shown as ``n/a``: the record ended first).

    Parameters
    ----------
    metrics : dict
        Its result.

    Returns
    -------
    str
        ``turning circle (starboard): advance 12.3 m, ...`` or ``zig-zag 20/20: ...``.
    """
    import math

    def f(v, unit):
        return f"{v:.3g} {unit}" if isinstance(v, float) and math.isfinite(v) else "n/a"

    if metrics["manoeuvre"] == "zigzag":
        return (f"zig-zag (reversal at {metrics['zigzag_psi_deg']:.3g} deg): overshoots {f(metrics['overshoot_1_deg'], 'deg')}, "
                f"{f(metrics['overshoot_2_deg'], 'deg')}; initial turning time {f(metrics['initial_turning_time_s'], 's')}, "
                f"period {f(metrics['period_s'], 's')} (ITTC 7.5-04-02-01)")
    return (f"turning circle ({metrics['turn']}): advance {f(metrics['advance_m'], 'm')}, transfer "
            f"{f(metrics['transfer_m'], 'm')}, tactical diameter {f(metrics['tactical_diameter_m'], 'm')}, steady "
            f"turning diameter {f(metrics['steady_diameter_m'], 'm')} (ITTC 7.5-04-02-01)")
