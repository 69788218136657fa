"""The objective of a tuning: the benchmark's per-run score of a candidate on a split's runs.

The runs are planned by the suite (:meth:`auvtrack.benchmark.suite.Suite.conditions`, the same
conditions a comparison flies, at the split's seed indices), flown by the comparison's
:func:`auvtrack.benchmark.execute.run_chunk` and scored by :meth:`Suite.run_score` after
:func:`auvtrack.benchmark.leaderboard.derive_metrics`: tuning optimises exactly what is judged.
The objective of a candidate is the mean run score over the split's runs (lower is better).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Mapping, Sequence

__all__ = ["TUNING_SPLITS", "split_conditions", "split_specs", "score_table", "Evaluation", "evaluate",
           "candidate_table"]

TUNING_SPLITS = ("training", "validation")
"""The splits a tuning may fly; never the evaluation seeds."""


def candidate_table(base: Mapping[str, Any], gains: Mapping[str, float]) -> dict:
    """The ``[controller]`` table of a candidate: ``base`` with ``gains`` set (a plug-in's under ``params``).

    Parameters
    ----------
    base : mapping
        ``kind`` (and ``module`` for a plug-in, other fixed keys).
    gains : mapping of str to float or list of float
        The candidate's field values (:func:`auvtrack.tuning.space.field_values`).

    Returns
    -------
    dict
        The table.
    """
    values = {k: [float(x) for x in v] if isinstance(v, (list, tuple)) else float(v) for k, v in gains.items()}
    table = dict(base)
    if table.get("kind") == "plugin":
        table["params"] = {**dict(table.get("params") or {}), **values}
    else:
        table.update(values)
    return table


def split_conditions(suite, split: str) -> list[tuple[str, str, int, tuple[dict, dict, dict]]]:
    """What every run of ``split`` imposes whatever the controller (:meth:`Suite.conditions`), in run order.

    A tuning computes them once and builds each candidate's runs on them (:func:`split_specs`):
    only the ``[controller]`` table differs between candidates.

    Parameters
    ----------
    suite : auvtrack.benchmark.suite.Suite
        The suite.
    split : str
        ``"training"`` or ``"validation"``.

    Returns
    -------
    list of (str, str, int, tuple)
        Task, tier, seed index and the conditions; cell-major (task, tier), then seed index.

    Raises
    ------
    ValueError
        ``split`` is the evaluation split or unknown, or a seed index of it is an evaluation seed.
    """
    if split not in TUNING_SPLITS:
        raise ValueError(f"split: must be one of {', '.join(TUNING_SPLITS)} (got {split!r}): a tuning never "
                         "flies the evaluation seeds")
    seeds = suite.split_seeds(split)
    out = []
    for task, tier in suite.split_cells(split):
        for i in seeds:
            if suite.split_of(i) != split:
                raise ValueError(f"splits.{split}: seed index {i} belongs to the {suite.split_of(i)} split")
            out.append((task, tier, i, suite.conditions(task, tier, i)))
    return out


def split_specs(suite, table: Mapping[str, Any], split: str, label: str = "candidate", *,
                conditions: Sequence[tuple[str, str, int, tuple[dict, dict, dict]]] | None = None) -> list:
    """The runs of ``split`` for one controller table, as the comparison's ``RunSpec`` records.

    Parameters
    ----------
    suite : auvtrack.benchmark.suite.Suite
        The suite.
    table : mapping
        The ``[controller]`` table flown.
    split : str
        ``"training"`` or ``"validation"``.
    label : str, optional
        The controller label in the rows.
    conditions : sequence, optional
        ``split_conditions(suite, split)`` when already computed (a tuning's trials share them).

    Returns
    -------
    list of RunSpec
        Cell-major (task, tier), then seed index.

    Raises
    ------
    ValueError
        ``split`` is the evaluation split or unknown, or a seed index of it is an evaluation seed.
    """
    from ..benchmark.execute import RunSpec
    from ..benchmark.suite import ControllerEntry

    if conditions is None:
        conditions = split_conditions(suite, split)
    elif split not in TUNING_SPLITS:
        raise ValueError(f"split: must be one of {', '.join(TUNING_SPLITS)} (got {split!r}): a tuning never "
                         "flies the evaluation seeds")
    entry = ControllerEntry(label, dict(table), "tuning candidate")
    specs = []
    for r, (task, tier, i, cond) in enumerate(conditions):
        raw, ov, drawn = suite.scenario(entry, task, tier, i, cond)
        specs.append(RunSpec(r, label, task, tier, i, raw, ov, drawn))
    return specs


def score_table(suite, table) -> list[float]:
    """The benchmark's score of each run of a runs table (:meth:`Suite.run_score`).

    Parameters
    ----------
    suite : auvtrack.benchmark.suite.Suite
        The suite (its ``[run_score]`` and ``[metrics]`` settings).
    table : pyarrow.Table
        Rows of :func:`auvtrack.benchmark.execute.run_chunk`.

    Returns
    -------
    list of float
        One score per row, in order.
    """
    from ..benchmark.leaderboard import derive_metrics

    df = derive_metrics(table.to_pandas(), settle=suite.file.metrics.settle)
    return [suite.run_score(row, row["task"]) for row in df.to_dict("records")]


@dataclass
class Evaluation:
    """A candidate flown on some runs of a split.

    Attributes
    ----------
    scores : list of float
        One per run flown, in plan order.
    runs : int
        Runs flown.
    steps : int
        RK4 steps integrated.
    failed : int
        Runs that did not complete.
    stopped_early : bool
        Whether runs were left unflown because one failed (pruning).
    rows : list of dict
        The runs table's rows (status, cause, metrics).
    """

    scores: list[float] = field(default_factory=list)
    runs: int = 0
    steps: int = 0
    failed: int = 0
    stopped_early: bool = False
    rows: list[dict] = field(default_factory=list)

    @property
    def score(self) -> float:
        """Mean run score (NaN when nothing was flown)."""
        return math.fsum(self.scores) / len(self.scores) if self.scores else math.nan


def evaluate(suite, specs: Sequence, *, chunk: int | None = None, stop_on_failure: bool = False,
             workers: int | None = 1, backend: str | None = None, on_chunk=None,
             plant_cache: dict | None = None) -> Evaluation:
    """Fly ``specs`` with the comparison's executor and score them with the benchmark's score.

    Parameters
    ----------
    suite : auvtrack.benchmark.suite.Suite
        The suite.
    specs : sequence of RunSpec
        From :func:`split_specs`.
    chunk : int, optional
        Runs per batch (default: all at once).
    stop_on_failure : bool, optional
        Stop after the first batch holding a failed run (a failing candidate is pruned early).
    workers : int or None, optional
        Threads of the batch runner.
    backend : str, optional
        Back end of the batch runner.
    on_chunk : callable, optional
        ``on_chunk(evaluation)`` after each batch (progress, Optuna's intermediate values).
    plant_cache : dict, optional
        Plant set-ups shared by the candidates of a tuning (:func:`auvtrack.benchmark.execute.run_chunk`).

    Returns
    -------
    Evaluation
        Scores, runs, steps and failures.
    """
    from ..benchmark.execute import run_chunk

    ev = Evaluation()
    size = chunk or max(len(specs), 1)
    for start in range(0, len(specs), size):
        table = run_chunk(specs[start:start + size], workers=workers, backend=backend, plant_cache=plant_cache)
        ev.scores += score_table(suite, table)
        rows = table.to_pylist()
        ev.rows += rows
        ev.runs += len(rows)
        ev.steps += sum(int(r["steps"]) for r in rows)
        ev.failed += sum(r["status"] != "ok" for r in rows)
        if on_chunk is not None:
            on_chunk(ev)
        if stop_on_failure and ev.failed and start + size < len(specs):
            ev.stopped_early = True
            break
    return ev
