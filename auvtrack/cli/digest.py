"""What the terminal shows after a long command: a few plain lines, the Markdown stays in the files."""
from __future__ import annotations

__all__ = ["sweep_lines", "reproduce_lines", "saturation_warning", "manoeuvre_metrics", "manoeuvre_line"]

AXES = {"u": "surge", "q": "pitch", "r": "yaw"}


def sweep_lines(summary: dict) -> list[str]:
    """Plain lines of a sweep summary (:func:`auvtrack.batch.sweep.summarize`): totals, then each group.

    Parameters
    ----------
    summary : dict
        The summary written to ``summary.json``.

    Returns
    -------
    list of str
        ``sweep <study>: <samples> samples, <counts>``, then one line per group of named grid values.
    """
    from ..batch.sweep import counts_text

    lines = [f"sweep {summary['study']}: {summary['samples']} samples, {counts_text(summary)}"]
    for g in summary.get("groups") or []:
        name = ", ".join(f"{k} = {v}" for k, v in g["key"].items())
        lines.append(f"  {name}: {g['samples']} samples, {counts_text(g)}")
    return lines


def reproduce_lines(metrics: dict) -> list[str]:
    """Plain lines of ``reproduce``'s ``metrics.json``: each run's status and each claim's verdict.

    Parameters
    ----------
    metrics : dict
        The document ``reproduce`` writes to ``metrics.json``.

    Returns
    -------
    list of str
        ``status:`` with each controller's, then ``<claim>: <verdict>`` for the default forms, then
        one line per form of the law with its verdicts in the claims' order.
    """
    lines = ["status: " + ", ".join(f"{k} {v}" for k, v in metrics["status"].items())]
    lines += [f"{v['claim']}: {v['verdict']}" for v in metrics["verdicts"]]
    for form in metrics.get("forms") or []:
        lines.append(f"  {form['label']}: " + " / ".join(v["verdict"] for v in form["verdicts"]))
    return lines


def saturation_warning(metrics: dict, duration: float) -> str | None:
    """A warning for a run whose status is ok although its inputs saturated, or None when none did.

    Parameters
    ----------
    metrics : dict
        The run's metrics (``t_sat_tau_j``: s the allocation could not produce τ_j;
        ``t_act_limit_j``: s actuator j sat at its limit; ``max_abs_x|y|z``: m; docs/metrics.md).
    duration : float
        The run's simulated time, s.

    Returns
    -------
    str or None
        ``status ok, but the inputs saturated: surge 1.7 s of 10 s, ...; largest position error 3 m (x)``.
    """
    parts = []
    for j, axis in AXES.items():
        t_sat, t_act = metrics.get(f"t_sat_tau_{j}", 0.0), metrics.get(f"t_act_limit_{j}", 0.0)
        if t_sat > 0 or t_act > 0:
            parts.append(f"{axis} {max(t_sat, t_act):.3g} s of {duration:.6g} s")
    if not parts:
        return None
    errors = {a: metrics.get(f"max_abs_{a}", 0.0) for a in "xyz"}
    worst = max(errors, key=errors.get)
    return (f"status ok, but the inputs saturated: {', '.join(parts)}; "
            f"largest position error {errors[worst]:.3g} m ({worst})")


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
