"""What the terminal shows after a long command: a few plain lines, the Markdown stays in the files."""
from __future__ import annotations

__all__ = ["sweep_lines", "reproduce_lines", "saturation_warning"]

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
