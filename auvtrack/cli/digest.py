"""What the terminal shows after a long command: a few plain lines, the Markdown stays in the files."""
from __future__ import annotations

__all__ = ["sweep_lines", "reproduce_lines"]


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
