"""What a tuning writes: the gain preset with its provenance, ``results.json`` and ``report.html``."""
from __future__ import annotations

import json
import math
import sys
import warnings
from dataclasses import asdict
from pathlib import Path
from typing import Any, Callable

__all__ = ["preset_name", "preset_text", "write_outputs"]


def preset_name(controller: dict, vehicle: str, suite: str) -> str:
    """``<controller>_<vehicle>_<suite>`` (a plug-in by its file name); characters outside names become ``_``.

    Parameters
    ----------
    controller : dict
        The tuned ``[controller]`` table.
    vehicle : str
        The suite's design vehicle preset.
    suite : str
        The suite's name.

    Returns
    -------
    str
        The preset name.
    """
    import re

    label = Path(controller["module"]).stem if controller["kind"] == "plugin" else controller["kind"]
    return re.sub(r"[^A-Za-z0-9_\-]", "_", f"{label}_{vehicle}_{suite}")


def _toml_value(v: Any) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, float):
        return repr(v) if math.isfinite(v) else ('"nan"' if math.isnan(v) else '"inf"')
    if isinstance(v, int):
        return str(v)
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_toml_value(x) for x in v) + "]"
    return json.dumps(str(v))


def preset_text(res, provenance: dict[str, Any]) -> str:
    """The gain preset file (``kind``, ``description``, ``[gains]``, ``[provenance]``) of a tuning.

    ``[gains]`` holds the best candidate's whole table (:attr:`TuneResult.table`): the searched
    gains and every other field, so the preset reproduces the controller that was tuned.

    Parameters
    ----------
    res : TuneResult
        The tuning (its best gains).
    provenance : dict
        Flat provenance keys (strings, numbers, lists).

    Returns
    -------
    str
        TOML text readable by :func:`auvtrack.control.gain_presets.get_gain_preset`.
    """
    kind = res.controller["kind"]
    desc = (f"{kind} gains tuned by auvtrack tune on {res.suite} version {res.suite_version} ({res.split} split, "
            f"{res.trials} trials)")
    table = {k: v for k, v in (res.table or res.best_params).items() if k != "kind"}
    nested = {k: v for k, v in table.items() if isinstance(v, dict)}
    lines = [f"kind = {_toml_value(kind)}", f"description = {_toml_value(desc)}", "", "[gains]"]
    lines += [f"{k} = {_toml_value(v)}" for k, v in table.items() if k not in nested]
    for k, sub in nested.items():
        lines += ["", f"[gains.{k}]"] + [f"{n} = {_toml_value(v)}" for n, v in sub.items()]
    lines += ["", "[provenance]"] + [f"{k} = {_toml_value(v)}" for k, v in provenance.items()]
    return "\n".join(lines) + "\n"


def _study(res):
    import optuna

    return optuna.load_study(study_name="tune", storage=res.study)


def write_outputs(res, out: str | Path, *, vehicle: str, suite_name: str, sampler: str, seed: int,
                  runs_per_trial: int, notify: Callable[[str], None] | None = None) -> dict[str, Path]:
    """Write the preset, ``results.json`` and the report of a finished tuning into ``out``.

    Parameters
    ----------
    res : TuneResult
        The tuning.
    out : str or Path
        Its output folder.
    vehicle, suite_name : str
        For the preset's name.
    sampler : str
        Sampler name.
    seed : int
        Sampler seed.
    runs_per_trial : int
        Training runs of one trial (the budget is trials x runs_per_trial).
    notify : callable, optional
        Receives one line when Optuna warns about the parameter importances (too few trials);
        default standard error.

    Returns
    -------
    dict of str to Path
        ``preset`` (absent when no trial completed), ``results``, ``report``, ``slices`` (the
        slice figure, absent when no trial finished).
    """
    import optuna

    from .. import __version__
    from .slices import slice_figure
    from ..jit import source_hash
    from ..report import Report, write_json

    out = Path(out)
    study = _study(res)
    trials = [{"number": t.number, "state": t.state.name, "value": t.value, "params": t.params,
               "user_attrs": t.user_attrs} for t in study.get_trials()]
    with warnings.catch_warnings(record=True) as caught:  # Optuna's warning becomes one line of ours
        warnings.simplefilter("always")
        try:
            importances = {k: float(v) for k, v in optuna.importance.get_param_importances(study).items()}
        except (RuntimeError, ValueError, ZeroDivisionError):  # too few complete trials
            importances = {}
    if caught:
        say = notify or (lambda text: print(text, file=sys.stderr, flush=True))
        say(f"note: parameter importances: {' '.join(str(caught[0].message).split())} ({res.trials} finished "
            f"trial{'s' if res.trials != 1 else ''})")
    cost = res.study_cost
    provenance = {"tool": "auvtrack tune", "suite": res.suite, "suite_version": res.suite_version,
                  "split": res.split, "budget_trials": res.trials, "runs_per_trial": runs_per_trial,
                  "budget_runs": res.trials * runs_per_trial, "sampler": sampler, "sampler_seed": seed,
                  "first_candidate": next((t["user_attrs"].get("first_candidate", "sampled") for t in trials
                                           if t["number"] == 0), "sampled"),
                  "optuna": optuna.__version__, "auvtrack": __version__, "source_hash": source_hash()[:16],
                  "train_score": res.best_score, "validation_score": res.validation_score,
                  "complete": res.complete, "pruned": res.pruned, "refused": res.refused,
                  # the whole study's cost (every process and every resumed call), not the last call's
                  "study_runs": cost.get("runs", 0), "study_rk4_steps": cost.get("steps", 0),
                  "cpu_s": round(cost.get("cpu_s", math.nan), 3), "wall_s": round(cost.get("elapsed_s", res.wall_s), 3),
                  "trials_wall_s": round(cost.get("wall_s", math.nan), 3),
                  "validation_runs": len(res.validation_runs),
                  "tuned": list(res.best_params)}
    paths: dict[str, Path] = {}
    if res.best_params:
        name = preset_name(res.controller, vehicle, suite_name)
        paths["preset"] = out / f"{name}.toml"
        paths["preset"].write_text(preset_text(res, provenance))
    paths["results"] = write_json(out / "results.json", {"result": asdict(res), "provenance": provenance,
                                                        "importances": importances, "trials": trials})
    rep = Report(out, f"Tuning of {res.controller['kind']} on {res.suite} version {res.suite_version}")
    rep.paragraph(f"{res.trials} trials ({res.complete} complete, {res.pruned} pruned after a failed run, "
                  f"{res.refused} refused by a set-up condition) on the {res.split} split; {res.runs} runs, "
                  f"{res.steps} RK4 steps, {res.cpu_s:.1f} CPU s, {res.wall_s:.1f} wall s in this process.")
    rep.table(["", "score"], [["best training score", res.best_score],
                             ["validation-split score", res.validation_score]])
    rep.heading("Best gains")
    rep.table(["gain", "value", "importance"], [[k, v, importances.get(k, math.nan)] for k, v in res.best_params.items()])
    if res.validation_runs:
        rep.heading("The best gains' validation runs")
        rep.table(["task", "tier", "seed index", "status", "cause", "t_stop (s)", "score"],
                  [[r["task"], r["tier"], r["seed_index"], r["status"], r["cause"], r["t_stop"], r["score"]]
                   for r in res.validation_runs])
    fig = slice_figure(study)
    if fig is not None:
        rep.heading("Slices")
        paths["slices"] = rep.figure(fig, "slices", "Objective of every finished trial against each searched gain "
                                     "(complete: its score; refused by a set-up condition: the refusal score; "
                                     "pruned: the mean score of the runs flown before the failure).")
    rep.heading("Optimisation history")
    best, rows = math.inf, []
    for t in trials:
        if t["state"] == "COMPLETE" and t["value"] is not None:
            best = min(best, t["value"])
        rows.append([t["number"], t["state"], t["value"] if t["value"] is not None else math.nan, best])
    rep.table(["trial", "state", "score", "best so far"], rows)
    paths["report"] = rep.write("report.md", html="report.html")
    return paths
