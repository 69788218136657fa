"""The manoeuvre an open-loop run flew: turning-circle or zig-zag figures from its logged channels.

A controller that does not track a reference (``TRACKS = False``: ``open_loop``,
``open_loop_actuators``) flies a manoeuvre, so its tracking error means nothing; its result
carries these figures instead (``Result.meta["manoeuvre"]``, ``run.json``, the summary line).
"""
from __future__ import annotations

__all__ = ["manoeuvre_metrics", "manoeuvre_line"]


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

    from ..studies.manoeuvres import turning_circle_metrics, zigzag_metrics

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
