"""``auvtrack compare --tune``: a plug-in newcomer tuned like the built-ins before it is compared.

Each plug-in entry of a comparison is tuned by :func:`auvtrack.tuning.tune` on the suite's
training split with the suite's shared budget (the number of trials its shipped presets were
tuned with, read from their provenance) and enters the comparison with its best gains
(``params`` of its ``[controller]`` table).  The tuning lives in ``<out>-tune/<label>`` next to
the comparison's folder, so a stopped comparison resumes its tunings as well (an unchanged
study returns the same gains, and so the same comparison fingerprint).
"""
from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import Callable, Sequence

__all__ = ["shared_budget", "tune_folder", "tune_newcomers", "tuned_entries"]


def shared_budget(suite) -> int:
    """The number of trials the suite's shipped presets were tuned with (``auvtrack tune`` provenance).

    Parameters
    ----------
    suite : auvtrack.benchmark.suite.Suite
        The suite.

    Returns
    -------
    int
        The trials of every preset whose provenance names this suite and its version
        (``suite`` and ``suite_version``).

    Raises
    ------
    ValueError
        ``--tune: ...`` when no preset of the suite is installed or their budgets differ.
    """
    from ..control.gain_presets import available_gain_presets, get_gain_preset

    budgets = {}
    for name in available_gain_presets():
        prov = get_gain_preset(name).provenance or {}
        if (prov.get("tool") == "auvtrack tune" and prov.get("suite") == suite.name
                and prov.get("suite_version") == suite.file.version):
            budgets[name] = int(prov["budget_trials"])
    if not budgets:
        raise ValueError(f"--tune: no preset tuned on {suite.name} is installed to take the shared budget from; "
                         "give the trials, --tune N")
    if len(set(budgets.values())) > 1:
        listed = ", ".join(f"{k} {v}" for k, v in sorted(budgets.items()))
        raise ValueError(f"--tune: the presets of {suite.name} were tuned with different budgets ({listed}); "
                         "give the trials, --tune N")
    return next(iter(budgets.values()))


def tune_folder(out: str | Path) -> Path:
    """The folder holding a comparison's tunings: ``<out>-tune`` next to it.

    Parameters
    ----------
    out : str or Path
        The comparison's output folder.

    Returns
    -------
    Path
        ``<out>-tune``.
    """
    out = Path(out)
    return out.with_name(out.name + "-tune")


def tune_newcomers(suite, entries: Sequence, trials: int, out: str | Path, *, seed: int = 0,
                   workers: int | None = 1, progress: Callable[[str], None] | None = None,
                   quiet: bool = False) -> list:
    """The comparison's entries with every plug-in tuned on the suite's training split.

    Parameters
    ----------
    suite : auvtrack.benchmark.suite.Suite
        The suite compared on (tuned on its full variant's training split, the split the
        shipped presets were tuned on).
    entries : sequence of ControllerEntry
        The competitors; built-ins are kept as they are.
    trials : int
        Trials per plug-in (the shared budget).
    out : str or Path
        The comparison's folder (the tunings go to :func:`tune_folder`).
    seed : int, optional
        Sampler seed.
    workers : int or None, optional
        Threads of the batch runner inside a trial.
    progress : callable, optional
        Receives one line per finished tuning.
    quiet : bool, optional
        Tune silently (:func:`auvtrack.tuning.tune`'s ``quiet``: no compile notice, no Optuna log).

    Returns
    -------
    list of ControllerEntry
        The entries, each plug-in's table holding its tuned ``params``.
    """
    from .space import field_values, search_space
    from .study import _params_model, tune

    source = suite.source
    result = []
    for e in entries:
        if e.table.get("kind") != "plugin":
            result.append(e)
            continue
        res = tune(e.table["module"], source, trials=trials, out=tune_folder(out) / e.label, seed=seed,
                   workers=workers, quiet=quiet)
        if not res.best_params:
            raise ValueError(f"--tune: {e.label}: no trial of {trials} completed the training split "
                             f"({res.pruned} pruned, {res.refused} refused); see {tune_folder(out) / e.label}")
        tuned = field_values(search_space(_params_model(e.table)), res.best_params)
        table = {**e.table, "params": {**dict(e.table.get("params") or {}), **tuned}}
        gains = (f"plug-in {Path(e.table['module']).name}: tuned by auvtrack tune on {res.suite} training split, "
                 f"{res.trials} trials (train {res.best_score:.4g}, validation {res.validation_score:.4g})")
        result.append(dataclasses.replace(e, table=table, gains=gains))
        if progress is not None:
            progress(f"{e.label}: {gains}")
    return result


def tuned_entries(suite, controllers: list[str] | None, plugins: Sequence[str], budget: str, out: str | Path,
                  *, workers: int | None = None, progress: Callable[[str], None] | None = None,
                  quiet: bool = False) -> list:
    """The competitors of ``compare --tune``: built-ins as usual, plug-ins tuned at ``budget``.

    Parameters
    ----------
    suite : auvtrack.benchmark.suite.Suite
        The suite compared on.
    controllers : list of str or None
        ``--controllers`` (None: every tracking built-in).
    plugins : sequence of str
        ``--plugin`` files (at least one).
    budget : str
        ``"suite"`` (:func:`shared_budget`) or a number of trials.
    out : str or Path
        The comparison's folder.
    workers : int or None, optional
        Threads of the batch runner inside a trial (None: 1).
    progress : callable, optional
        One line per finished tuning.
    quiet : bool, optional
        Tune silently (``compare --quiet``).

    Returns
    -------
    list of ControllerEntry
        For :func:`auvtrack.benchmark.compare.compare`'s ``entries``.

    Raises
    ------
    ValueError
        ``--tune: ...`` (one line): no plug-in, a budget that is not a positive integer, no
        shared budget, a plug-in with no completed trial.
    """
    from ..benchmark.suite import resolve_controllers

    if not plugins:
        raise ValueError("--tune: tunes the --plugin newcomers; give at least one --plugin FILE.py")
    if budget == "suite":
        trials = shared_budget(suite)
    elif budget.isdigit() and int(budget) >= 1:
        trials = int(budget)
    else:
        raise ValueError(f"--tune: must be a number of trials >= 1, or no value for the suite's shared budget "
                         f"(got {budget!r})")
    entries = resolve_controllers(controllers, list(plugins), suite.file.gain_preset)
    return tune_newcomers(suite, entries, trials, out, workers=workers or 1, progress=progress, quiet=quiet)
