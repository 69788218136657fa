"""Slice plots of a tuning: the objective of every finished trial against each searched gain.

Read from the Optuna study (``study.db``): a complete trial at its score, a candidate refused by
a set-up condition at the refusal score (the run-score cap + 2), a pruned one at the mean score
of the runs it flew before the failure stopped it.  One panel per dimension, on the dimension's
own scale (logarithmic where it is searched so).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

__all__ = ["SlicePoint", "slice_points", "slice_figure"]


@dataclass(frozen=True)
class SlicePoint:
    """One trial in one slice.

    Attributes
    ----------
    trial : int
        Trial number.
    value : float
        The dimension's value in the trial.
    score : float
        Its objective (see the module docstring).
    state : str
        ``complete``, ``refused`` or ``pruned``.
    """

    trial: int
    value: float
    score: float
    state: str


def slice_points(study) -> dict[str, list[SlicePoint]]:
    """The finished trials of a tuning's study, per searched dimension.

    Parameters
    ----------
    study : optuna.Study
        The tuning's study.

    Returns
    -------
    dict of str to list of SlicePoint
        Dimension name -> one point per finished trial holding it, in trial order.
    """
    from optuna.trial import TrialState

    out: dict[str, list[SlicePoint]] = {}
    for t in study.get_trials(deepcopy=False, states=(TrialState.COMPLETE, TrialState.PRUNED)):
        if t.state == TrialState.PRUNED:
            steps = t.intermediate_values
            score, state = (steps[max(steps)] if steps else math.nan), "pruned"
        else:
            score, state = float(t.value), ("refused" if t.user_attrs.get("violations") else "complete")
        for name, v in t.params.items():
            out.setdefault(name, []).append(SlicePoint(t.number, float(v), float(score), state))
    return out


_STYLE = {"complete": ("o", "C0"), "pruned": ("x", "C1"), "refused": ("s", "C3")}


def slice_figure(study) -> Any:
    """A Matplotlib figure: one panel per dimension, the trials' objective against the gain.

    Parameters
    ----------
    study : optuna.Study
        The tuning's study.

    Returns
    -------
    matplotlib.figure.Figure or None
        None when no trial finished.
    """
    from matplotlib.figure import Figure

    points = slice_points(study)
    if not points:
        return None
    logs = {}
    for t in study.get_trials(deepcopy=False):
        for name, dist in t.distributions.items():
            logs[name] = bool(getattr(dist, "log", False))
    ncol = min(len(points), 3)
    nrow = -(-len(points) // ncol)
    fig = Figure(figsize=(4.0 * ncol, 3.0 * nrow))
    for i, (name, pts) in enumerate(points.items()):
        ax = fig.add_subplot(nrow, ncol, i + 1)
        for state, (marker, colour) in _STYLE.items():
            sel = [p for p in pts if p.state == state]
            if sel:
                ax.scatter([p.value for p in sel], [p.score for p in sel], marker=marker, color=colour, label=state)
        if logs.get(name):
            ax.set_xscale("log")
        ax.set_xlabel(name)
        ax.set_ylabel("objective (mean run score)")
        if i == 0:
            ax.legend(fontsize="small")
    fig.tight_layout()
    return fig
