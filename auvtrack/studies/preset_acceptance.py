"""The model-gap acceptance check of the shipped presets: do they complete the calm truth runs?

Each built-in tracking controller with a shipped preset (``<kind>_remus100_<suite>``, e.g.
``pid_remus100_auv-track-v2``) flies every calm (no current) run of ``auvtrack study
model-gap`` on the two 6-DOF truths (``prestero``, ``fossen``) whose task is feasible
(:func:`auvtrack.studies.model_gap.feasibility`): the study's own scenarios, with the preset's
``[controller]`` in place of the designed or published one.  The check holds for a controller
when every such run completes; a run that fails is reported with its cause and time, the
mechanism to explain.
"""
from __future__ import annotations

from dataclasses import dataclass, field

__all__ = ["AcceptanceRow", "acceptance_runs", "acceptance"]

TRUTHS = ("prestero", "fossen")
"""The model-gap study's 6-DOF truths (its ``5dof`` plant is the design model, not a truth)."""


@dataclass
class AcceptanceRow:
    """One calm truth run of a preset.

    Attributes
    ----------
    controller, preset, truth, reference : str
        What flew where.
    status : str
        ``ok``, ``failed``, ``infeasible`` (not flown: the task's binding check in ``cause``) or
        ``no preset``.
    cause : str or None
        Failure cause or binding check.
    fail_time : float or None
        Time of the failure (s).
    row : dict
        The model-gap study's result row (errors, actuator usage); empty when not flown.
    """

    controller: str
    preset: str
    truth: str
    reference: str
    status: str
    cause: str | None = None
    fail_time: float | None = None
    row: dict = field(default_factory=dict)


def acceptance_runs(suite: str = "auv-track-v2", quick: bool = False) -> list[tuple[str, str, str, str]]:
    """Every (controller, preset, truth, reference) the check flies.

    Parameters
    ----------
    suite : str
        The suite the presets were tuned on (their names end with it).
    quick : bool
        The study's quick references (the helix only) instead of all.

    Returns
    -------
    list of tuple
        One per controller (every tracking built-in), truth and reference.
    """
    from ..benchmark.suite import tracking_kinds
    from . import model_gap

    refs = ("helix",) if quick else tuple(model_gap.REFERENCES)
    return [(k, f"{k}_remus100_{suite}", t, r) for k in tracking_kinds() for t in TRUTHS for r in refs]


def acceptance(suite: str = "auv-track-v2", *, quick: bool = False, duration: float | None = None) -> list[AcceptanceRow]:
    """Fly the check (see the module docstring).

    Parameters
    ----------
    suite : str
        The suite the presets were tuned on.
    quick : bool
        The helix only, 20 s (the study's ``--quick``) instead of every reference, 150 s.
    duration : float, optional
        Run length (s) instead of the study's.

    Returns
    -------
    list of AcceptanceRow
        One per run of :func:`acceptance_runs`, in order.
    """
    from ..control.gain_presets import available_gain_presets
    from ..report import failure_cause
    from ..scenario import load_scenario
    from ..simulation.pipeline import prepare, run_prepared
    from . import model_gap

    duration = duration if duration is not None else (20.0 if quick else 150.0)
    shipped = set(available_gain_presets())
    tasks: dict = {}
    out = []
    for kind, preset, truth, ref in acceptance_runs(suite, quick):
        if preset not in shipped:
            out.append(AcceptanceRow(kind, preset, truth, ref, "no preset"))
            continue
        if (truth, ref) not in tasks:
            tasks[truth, ref] = model_gap.feasibility(truth, ref, False, duration)
        f = tasks[truth, ref]
        if f.verdict == "infeasible":
            out.append(AcceptanceRow(kind, preset, truth, ref, "infeasible", model_gap.binding_check(f)))
            continue
        sc = model_gap.scenario(kind, truth, ref, False, duration)
        sc["controller"] = {"kind": kind, "preset": preset}
        sc["name"] = sc["name"].replace("-designed-", "-preset-")
        loaded = load_scenario(sc)
        res = run_prepared(prepare(loaded))
        limits = loaded.plant.actuator_limits() if hasattr(loaded.plant, "actuator_limits") else None
        row = model_gap.summarise((kind, truth, ref, False, "preset"), res, limits)
        out.append(AcceptanceRow(kind, preset, truth, ref, res.status, failure_cause(res),
                                 res.failure["time"] if res.failure else None, row))
    return out
