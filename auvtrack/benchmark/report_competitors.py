"""The report's tables on the competitors and their failures: tuning budget and cost, gains, causes.

* :func:`tuning_rows`: each competitor's gain preset and its ``[provenance]`` (the tool, the
  suite and split it was tuned on, the budget and what it cost), a plug-in's ``compare --tune``
  tuning, or the package defaults; :func:`not_tuned_on`: those not tuned on the suite compared;
* :func:`gain_rows`: the gains a preset changes, next to the published values (the controller's
  ``Params`` defaults, docs/controllers.md);
* :func:`failure_cause_rows`: "why it failed": the failed runs per (tier, controller) by cause;
  a failure without a recorded cause counts under ``unknown``.
"""
from __future__ import annotations

import json
from pathlib import Path
from typing import Any, Mapping, Sequence

from ..report import fmt
from .suite import ControllerEntry

__all__ = ["tuning_rows", "not_tuned_on", "gain_rows", "failure_cause_rows", "TUNING_COLUMNS"]

TUNING_COLUMNS = ("competitor", "gains", "tuned by", "tuned on", "budget", "cost", "objective (train / validation)")
_UNKNOWN = "unknown"


def _preset(entry: ControllerEntry):
    from ..control.gain_presets import get_gain_preset

    name = entry.table.get("preset")
    return None if name is None else get_gain_preset(str(name))


def _budget(p: Mapping[str, Any]) -> str:
    if "budget_trials" in p:
        return f"{p['budget_trials']} trials x {p.get('runs_per_trial', '?')} runs = {p.get('budget_runs', '?')} runs"
    if "evaluations" in p:
        return f"{p['evaluations']} evaluations"
    return "not recorded"


def _cost(p: Mapping[str, Any]) -> str:
    parts = []
    if "study_runs" in p:
        parts.append(f"{p['study_runs']} runs flown")
    if "study_rk4_steps" in p:
        parts.append(f"{p['study_rk4_steps']:.3g} RK4 steps")
    if "wall_s" in p:
        parts.append(f"{fmt(p['wall_s'], 3)} s wall")
    return ", ".join(parts) or "not recorded"


def _objective(p: Mapping[str, Any]) -> str:
    for train, val in (("train_score", "validation_score"), ("train_objective", "validation_objective")):
        if train in p:
            return f"{fmt(p[train], 4)} / {fmt(p[val], 4) if val in p else 'n/a'}"
    return "n/a"


def _plugin_tuning(entry: ControllerEntry, tuned_dir: Path | None) -> Mapping[str, Any] | None:
    """The provenance of a plug-in's ``compare --tune`` tuning (``<tuned_dir>/<label>/results.json``), if it ran."""
    path = None if tuned_dir is None else Path(tuned_dir) / entry.label / "results.json"
    if path is None or "params" not in entry.table or not path.is_file():
        return None
    return json.loads(path.read_text()).get("provenance")


def _suite_id(provenance: dict) -> str:
    """The suite a tuning ran on, as ``"<name> v<version>"`` (``auvtrack tune`` records the two apart)."""
    suite = str(provenance["suite"])
    return f"{suite} v{provenance['suite_version']}" if "suite_version" in provenance else suite


def tuning_rows(entries: Sequence[ControllerEntry], tuned_dir: Path | None = None) -> list[list[str]]:
    """One row per competitor (:data:`TUNING_COLUMNS`) from its gain preset's provenance.

    Parameters
    ----------
    entries : sequence of ControllerEntry
        The competitors.
    tuned_dir : Path, optional
        Where ``compare --tune`` tuned the plug-ins (``<out>-tune``): a plug-in entering with tuned
        ``params`` takes its row from the provenance of that tuning.

    Returns
    -------
    list of list of str
        Competitor, gains (preset or defaults), the tool, what it was tuned on (suite and split),
        the budget, the cost and the objective on the training and validation seeds.
    """
    rows = []
    for e in entries:
        plugin = e.table.get("kind") == "plugin"
        p = _plugin_tuning(e, tuned_dir) if plugin else None
        preset = None if plugin else _preset(e)
        if p is None and preset is None:
            what = "plug-in Params defaults" if plugin else "package defaults"
            rows.append([e.label, what, "not tuned", "", "0", "", ""])
            continue
        if p is None:
            p = preset.provenance
        tool = str(p.get("tool") or p.get("study") or "not recorded")
        on = f"{_suite_id(p)}, {p.get('split', '?')} split" if "suite" in p else \
            ", ".join(map(str, p.get("train_cases", []))) or "not recorded"
        gains = "tuned params (`compare --tune`)" if preset is None else f"preset {preset.name}"
        rows.append([e.label, gains, tool, on, _budget(p), _cost(p), _objective(p)])
    return rows


def not_tuned_on(rows: Sequence[Sequence[str]], suite: str) -> list[str]:
    """Competitors of :func:`tuning_rows` whose gains were not tuned on ``suite`` ("<name> v<version>").

    Parameters
    ----------
    rows : sequence of rows
        :func:`tuning_rows`.
    suite : str
        The suite as tuning names it (``auvtrack tune`` provenance ``suite``).

    Returns
    -------
    list of str
        Their labels, in the rows' order.
    """
    return [r[0] for r in rows if r[2] != "auvtrack tune" or not str(r[3]).startswith(f"{suite}, ")]


def gain_rows(entries: Sequence[ControllerEntry]) -> list[list[str]]:
    """The gains each preset sets to other values than the published ones, side by side.

    Parameters
    ----------
    entries : sequence of ControllerEntry
        The competitors (plug-ins and competitors without a preset have no row).

    Returns
    -------
    list of list of str
        ``[competitor, gain, published (Params default), preset value, preset]``, one row per
        gain that differs.
    """
    from ..control import CONTROLLERS

    rows = []
    for e in entries:
        kind = e.table.get("kind")
        preset = None if kind == "plugin" or kind not in CONTROLLERS else _preset(e)
        if preset is None:
            continue
        published = CONTROLLERS[kind].params.model_validate({"kind": kind})
        for k, v in preset.gains.items():
            ref = getattr(published, k, None)
            if ref != v:
                rows.append([e.label, k, fmt(ref, 4) if ref is not None else "n/a", fmt(v, 4), preset.name])
    return rows


def failure_cause_rows(pooled_tier: Sequence[Mapping[str, Any]]) -> tuple[list[str], list[list[Any]]]:
    """"Why it failed": the failed runs of each (tier, controller) that failed at all, by cause.

    Parameters
    ----------
    pooled_tier : sequence of dict
        ``analysis["pooled_tier"]`` (:func:`auvtrack.benchmark.leaderboard.pooled_failures`).

    Returns
    -------
    (list of str, list of list)
        The header (tier, controller, failed, one column per cause seen, ``unknown`` last) and
        the rows; the counts of a row add up to its failures.
    """
    causes = sorted({c for r in pooled_tier for c in r["causes"]} - {_UNKNOWN})
    if any(_UNKNOWN in r["causes"] for r in pooled_tier):
        causes.append(_UNKNOWN)
    rows = [[r["tier"], r["controller"], f"{r['failures']}/{r['n']}"] + [r["causes"].get(c, 0) for c in causes]
            for r in pooled_tier if r["failures"]]
    return ["tier", "controller", "failed"] + causes, rows
