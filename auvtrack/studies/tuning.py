"""``auvtrack study tuning``: fair tuning of every built-in closed-loop controller.

Every controller (the paper's FXTNTSMC and the baselines FTSMC, PID, backstepping, STA and PPC)
gets the **same** optimiser (Optuna's TPE, the optimiser of ``auvtrack tune``, fixed seed, the
package defaults as the first trial, batches of 24 candidates asked together and flown in
threads), the **same** budget (the same number of closed-loop evaluations whether it tunes three
gains or four), the **same**
objective and the **same** training scenarios (Section 4 and two variations).  The tuned gains are then evaluated on
held-out scenarios that the optimiser never saw, and written as gain presets
(``auvtrack/data/gains/<kind>_tuned.toml`` shape) usable from any scenario as
``controller.preset``.  Procedure, numbers and how to rerun: ``docs/tuning.md``.

Objective of one run (lower is better; all terms over the whole run)::

    J = w_itae * sum_i ITAE_i + w_energy * sum_j int tau_j^2 dt + w_tv * sum_j TV_j

with ITAE in m s^2, energy in N^2 s (N^2 m^2 s for moments) and TV the total variation of tau
per second on a 10 ms grid.  A run that fails (pitch limit, divergence, envelope violation)
costs ``penalty * (2 - t_fail / duration)``, more than any finite run and decreasing the
longer the run survived; a candidate that the controller's own conditions refuse (Theorem 1
for the FXTNTSMC, the ``setup`` gain checks of the others: the constraints of ``auvtrack tune``,
:func:`auvtrack.tuning.space.constraint_violations`) costs ``3 * penalty``.  The objective
of a gain vector is the mean of J over the scenarios.
"""
from __future__ import annotations

import json
import math
import time
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any, Callable, Sequence

import numpy as np
from ..batch.runner import stoppable_pool
from ..control import get as get_controller
from ..scenario import load_scenario
from ..simulation.compiling import compile_first
from ..simulation.pipeline import prepare, run_prepared
from .registry import StudySpec
from ..report import Report, write_json

__all__ = ["GainSpace", "Objective", "Case", "Budget", "SPACES", "TRAIN_CASES", "HELDOUT_CASES",
           "case_scenario", "run_cost", "tune", "evaluate", "preset_toml", "run", "STUDY"]

AXES = ("x", "y", "z")
INPUTS = ("u", "q", "r")


# --------------------------------------------------------------------------- search spaces

@dataclass(frozen=True)
class GainSpace:
    """The gains of one controller that the optimiser varies, with their box bounds.

    Attributes
    ----------
    kind : str
        Controller kind (``[controller] kind``).
    names : tuple of str
        Scenario keys of the tuned gains.
    bounds : tuple of (float, float)
        Box of each gain in physical units.
    log : tuple of bool
        Search in log space (gains spanning decades) or linearly (exponents).
    """

    kind: str
    names: tuple[str, ...]
    bounds: tuple[tuple[float, float], ...]
    log: tuple[bool, ...]

    def to_gains(self, u: Sequence[float]) -> dict[str, float]:
        """Map a search vector (log coordinates where ``log``) to gains by name.

        Parameters
        ----------
        u : sequence of float
            Search coordinates, one per gain.

        Returns
        -------
        dict of str to float
            Gains by scenario key.
        """
        return {n: float(math.exp(x) if lg else x) for n, x, lg in zip(self.names, u, self.log)}

    def to_search(self, gains: dict[str, float]) -> np.ndarray:
        """Map gains by name to search coordinates (inverse of :meth:`to_gains`).

        Parameters
        ----------
        gains : dict of str to float
            A value for every name of :attr:`names`.

        Returns
        -------
        numpy.ndarray
            Search coordinates.
        """
        return np.array([math.log(gains[n]) if lg else gains[n] for n, lg in zip(self.names, self.log)])

    def search_bounds(self) -> list[tuple[float, float]]:
        """Bounds in search coordinates."""
        return [(math.log(lo), math.log(hi)) if lg else (lo, hi) for (lo, hi), lg in zip(self.bounds, self.log)]

    def defaults(self) -> dict[str, float]:
        """The package's default values of the tuned gains (the optimiser's first candidate)."""
        model = get_controller(self.kind).params
        return {n: float(model.model_fields[n].default) for n in self.names}


# One-to-one counterparts: switching gain k1 <-> kappa1, linear reaching gain k2 <-> kappa3,
# surface weight beta <-> a1, surface exponent gamma <-> alpha.  The FXTNTSMC box keeps every
# condition of Theorem 1 (kappa3 > 0.5; 0.5 < alpha, a2 alpha < 1 and a4 alpha > 1 with the
# paper's a2 = 0.8, a4 = 2); the objective re-checks them (auvtrack.tuning.space.constraint_violations).
# The baselines tune their three loop gains (docs/controllers.md) in boxes spanning two decades or
# more around the defaults (the integral and adaptation gains down to 1e-4, near switched off); the PID's ki >= kd kp and the STA's Moreno-Osorio condition
# (with the default L) cut parts of their boxes, which setup refuses and the objective penalises.
SPACES: dict[str, GainSpace] = {
    "ftsmc": GainSpace("ftsmc", ("beta", "gamma", "k1", "k2"),
                       ((0.05, 20.0), (1.05, 1.95), (1e-3, 1.0), (0.05, 20.0)), (True, False, True, True)),
    "fxtntsmc": GainSpace("fxtntsmc", ("kappa1", "kappa3", "a1", "alpha"),
                          ((1e-3, 1.0), (0.51, 20.0), (0.05, 20.0), (0.55, 1.2)), (True, True, True, False)),
    "pid": GainSpace("pid", ("kp", "ki", "kd"), ((0.1, 30.0), (1e-4, 30.0), (0.1, 30.0)), (True, True, True)),
    "backstepping": GainSpace("backstepping", ("c1", "c2", "gamma"),
                              ((0.05, 20.0), (0.05, 20.0), (1e-4, 50.0)), (True, True, True)),
    "sta": GainSpace("sta", ("lam", "k1", "k2"), ((0.05, 20.0), (0.05, 20.0), (0.01, 20.0)), (True, True, True)),
    "ppc": GainSpace("ppc", ("kp", "kd", "l"), ((0.5, 200.0), (0.5, 50.0), (0.05, 2.0)), (True, True, True)),
}


# --------------------------------------------------------------------------- objective

@dataclass(frozen=True)
class Objective:
    """Weights of the tuning objective (see the module docstring).

    The weights put the three terms on the same order of magnitude for the paper's FXTNTSMC
    on Section 4 (30 s): ITAE ~ 7 m s^2, energy ~ 2.6e5 N^2 s -> ~5, TV ~ 170 N/s -> ~3.
    """

    w_itae: float = 1.0
    w_energy: float = 2e-5
    w_tv: float = 2e-2
    penalty: float = 1e3

    def cost(self, status: str, failure: dict | None, metrics: dict, duration: float) -> float:
        """J of one run: the weighted sum, or the failure penalty.

        Parameters
        ----------
        status : str
            ``"ok"`` or ``"failed"``.
        failure : dict or None
            The run's failure record (its ``time`` is used).
        metrics : dict
            The run's metrics (``itae_*``, ``energy_tau_*``, ``tv_tau_*``).
        duration : float
            Scheduled run length (s).

        Returns
        -------
        float
            J (a non-finite metric counts as twice the penalty).
        """
        if status != "ok":
            t = failure["time"] if failure else 0.0
            return self.penalty * (2.0 - min(max(t / duration, 0.0), 1.0))
        total = (self.w_itae * sum(metrics[f"itae_{a}"] for a in AXES)
                 + self.w_energy * sum(metrics[f"energy_tau_{j}"] for j in INPUTS)
                 + self.w_tv * sum(metrics[f"tv_tau_{j}"] for j in INPUTS))
        return float(total) if math.isfinite(total) else 2.0 * self.penalty


# --------------------------------------------------------------------------- scenarios

@dataclass(frozen=True)
class Case:
    """One tuning or evaluation scenario: Section 4 with the stated changes.

    Attributes
    ----------
    name : str
        Short label.
    seed : int
        Scenario seed (RBF centres and weights of the FXTNTSMC).
    eta0 : tuple of 5 float
        Initial [x, y, z, theta, psi] (m, rad).
    amplitude, phase : float
        Scale and phase (rad) of the paper's disturbance.
    extra : dict
        Further scenario sections (e.g. ``reference``, ``uncertainty``, ``vehicle``).
    """

    name: str
    seed: int = 0
    eta0: tuple[float, ...] = (0.0, 0.5, 0.0, 0.0, 0.0)
    amplitude: float = 1.0
    phase: float = 0.0
    extra: dict = field(default_factory=dict)


TRAIN_CASES: tuple[Case, ...] = (
    Case("sec4"),
    Case("sec4-phase", seed=1, eta0=(0.0, -0.5, 0.3, 0.0, 0.2), amplitude=1.5, phase=math.pi / 2),
    Case("sec4-offset", seed=2, eta0=(1.0, 1.0, -0.2, 0.0, -0.3), amplitude=0.75, phase=math.pi),
)
HELDOUT_CASES: tuple[Case, ...] = (
    Case("heldout-helix", seed=3, eta0=(-0.5, 0.8, 0.2, 0.0, 0.3), amplitude=1.25, phase=2.0,
         extra={"uncertainty": {"M": 0.1, "C": 0.2, "D": -0.1}}),
    Case("heldout-circle", seed=4, eta0=(0.5, -0.3, 1.0, 0.0, 0.0), amplitude=1.0, phase=0.7,
         extra={"reference": {"kind": "circle", "radius": 5.0, "omega": 0.08, "depth": 1.5}}),
)
PAPER_CASE = Case("sec4-100s")


@dataclass(frozen=True)
class Budget:
    """Optimiser budget and run length, identical for every controller.

    Attributes
    ----------
    popsize : int
        Batch multiplier for four gains: every controller asks :attr:`population` = popsize x 4
        candidates per batch (a three-gain space ceil(population / 3) x 3, see :meth:`de_popsize`;
        the budget of the study's earlier differential evolution, kept so its results compare).
    maxiter : int
        Generations after the initial population.
    seed : int
        Optimiser seed.
    duration, heldout_duration, dt : float
        Run length of the training and held-out runs, and the RK4 step (s).
    n_train : int
        Number of :data:`TRAIN_CASES` used.
    """

    popsize: int = 6
    maxiter: int = 14
    seed: int = 0
    duration: float = 30.0
    heldout_duration: float = 60.0
    dt: float = 0.001
    n_train: int = 3

    @property
    def population(self) -> int:
        """Candidates per batch, the same for every controller: popsize x 4."""
        return self.popsize * 4

    @property
    def max_evaluations(self) -> int:
        """Gain vectors evaluated for four gains: popsize x 4 x (maxiter + 1)."""
        return self.population * (self.maxiter + 1)

    def de_popsize(self, n_gains: int) -> int:
        """The batch multiplier for ``n_gains`` gains: ceil(population / n_gains)."""
        return -(-self.population // n_gains)

    def evaluations(self, n_gains: int) -> int:
        """Gain vectors evaluated for ``n_gains`` gains (= :attr:`max_evaluations` when n divides the population)."""
        return self.de_popsize(n_gains) * n_gains * (self.maxiter + 1)


FULL = Budget()
QUICK = Budget(popsize=2, maxiter=1, duration=4.0, heldout_duration=4.0, dt=0.002, n_train=1)


def case_scenario(case: Case, kind: str, gains: dict[str, float], duration: float, dt: float,
                  preset: str | None = None) -> dict[str, Any]:
    """Scenario dict of ``case`` for controller ``kind`` with ``gains`` (Section 4 elsewhere).

    Parameters
    ----------
    case : Case
        The scenario variation.
    kind : str
        Controller kind.
    gains : dict of str to float
        ``[controller]`` keys.
    duration, dt : float
        Run length and RK4 step (s).
    preset : str, optional
        Gain preset (``controller.preset``).

    Returns
    -------
    dict
        Input of :func:`auvtrack.scenario.load_scenario`.
    """
    ctrl: dict[str, Any] = {"kind": kind, **gains}
    if preset is not None:
        ctrl["preset"] = preset
    sc: dict[str, Any] = {
        "name": f"tuning-{case.name}-{kind}", "seed": case.seed,
        "sim": {"duration": duration, "dt": dt, "log_dt": dt * round(0.1 / dt) if dt < 0.1 else dt},
        "initial": {"eta": list(case.eta0)},
        "controller": ctrl,
        "disturbance": [{"kind": "paper", "amplitude": case.amplitude, "phase": case.phase}],
    }
    for key, value in case.extra.items():
        sc[key] = value
    return sc


def run_cost(case: Case, kind: str, gains: dict[str, float], duration: float, dt: float,
             objective: Objective) -> tuple[float, dict]:
    """Simulate one case and score it.

    Parameters
    ----------
    case : Case
        The scenario variation.
    kind : str
        Controller kind.
    gains : dict of str to float
        ``[controller]`` keys.
    duration, dt : float
        Run length and RK4 step (s).
    objective : Objective
        Weights of J.

    Returns
    -------
    tuple of (float, dict)
        J and a record with ``status``, ``failure`` (time, cause), ``J`` and the metrics used.

    Raises
    ------
    ValueError
        If the controller's ``setup`` refuses the gains (a gain condition).
    """
    res = run_prepared(prepare(load_scenario(case_scenario(case, kind, gains, duration, dt))))
    cost = objective.cost(res.status, res.failure, res.metrics, duration)
    keep = {k: res.metrics[k] for k in res.metrics
            if k.startswith(("itae_", "energy_tau_", "tv_tau_", "rmse_", "settle_1cm_"))}
    return cost, {"status": res.status,
                  "failure": None if res.failure is None else
                  {"time": res.failure["time"], "cause": res.failure["cause"]},
                  "J": cost, "metrics": keep}


# --------------------------------------------------------------------------- optimiser

@dataclass
class TuneResult:
    """Outcome of :func:`tune` for one controller."""

    kind: str
    gains: dict[str, float]
    train_objective: float
    start_gains: dict[str, float]
    start_objective: float
    nfev: int
    nit: int
    wall_s: float
    history: list[float]


def _rounded(gains: dict[str, float], digits: int = 4) -> dict[str, float]:
    return {k: float(f"{v:.{digits}g}") for k, v in gains.items()}


def _threads(workers: int | None) -> int:
    """Threads of a pool: ``workers``, or the batch runner's :func:`~auvtrack.batch.runner.default_workers`."""
    from ..batch.runner import default_workers

    return default_workers() if workers is None else max(1, workers)


def tune(kind: str, budget: Budget = FULL, objective: Objective = Objective(), *,
         cases: Sequence[Case] | None = None, workers: int | None = None,
         progress: Callable[[str], None] | None = None) -> TuneResult:
    """Tune the gains of ``kind`` with Optuna's seeded TPE (the package defaults first).

    Parameters
    ----------
    kind : str
        Controller, a key of :data:`SPACES`.
    budget : Budget, optional
        Population, generations, seed and run length (the same for every controller).
    objective : Objective, optional
        Weights of J.
    cases : sequence of Case, optional
        Training scenarios (default: the first ``budget.n_train`` of :data:`TRAIN_CASES`).
    workers : int, optional
        Threads evaluating a batch (the compiled kernel releases the GIL; default
        :func:`auvtrack.batch.runner.default_workers`); the result does not depend on it.
    progress : callable, optional
        Called with a one-line status after each batch.

    Returns
    -------
    TuneResult
        Best gains (rounded to 4 significant digits; ``train_objective`` is re-evaluated
        with the rounded gains), the default gains' objective, evaluations used.
    """
    if kind not in SPACES:
        raise ValueError(f"kind: must be one of {sorted(SPACES)} (got {kind!r})")
    import optuna

    from ..tuning.space import Dimension, constraint_violations, distributions

    space = SPACES[kind]
    cases = tuple(TRAIN_CASES[: budget.n_train] if cases is None else cases)

    def mean_cost(gains: dict[str, float]) -> float:
        if constraint_violations(load_scenario(case_scenario(cases[0], kind, gains, budget.duration, budget.dt))):
            return 3.0 * objective.penalty  # refused at set-up: Theorem 1, the gain checks
        return float(np.mean([run_cost(c, kind, gains, budget.duration, budget.dt, objective)[0] for c in cases]))

    start = space.defaults()
    dists = distributions({n: Dimension(n, lo, hi, lg, start[n])
                           for n, (lo, hi), lg in zip(space.names, space.bounds, space.log)})
    optuna.logging.set_verbosity(optuna.logging.WARNING)
    study = optuna.create_study(direction="minimize", sampler=optuna.samplers.TPESampler(seed=budget.seed))
    study.enqueue_trial(start)
    total, batch = budget.evaluations(len(space.names)), budget.population
    history: list[float] = []
    wall = time.perf_counter()
    with stoppable_pool(_threads(workers)) as pool:
        while len(study.trials) < total:  # a batch is asked before any is told: threads do not change it
            trials = [study.ask(dists) for _ in range(min(batch, total - len(study.trials)))]
            for t, value in zip(trials, pool.map(lambda t: mean_cost(dict(t.params)), trials)):
                study.tell(t, value)
            history.append(float(study.best_value))
            if progress:
                progress(f"{kind}: batch {len(history)}/{budget.maxiter + 1}, best J = {history[-1]:.4g}")
    wall = time.perf_counter() - wall
    best = min(study.trials, key=lambda t: (t.value, t.number))
    gains = _rounded({n: float(best.params[n]) for n in space.names})
    return TuneResult(kind=kind, gains=gains, train_objective=mean_cost(gains), start_gains=start,
                      start_objective=mean_cost(start), nfev=len(study.trials), nit=len(history),
                      wall_s=wall, history=history)


def evaluate(kind: str, gains: dict[str, float], cases: Sequence[Case], duration: float, dt: float,
             objective: Objective = Objective(), workers: int | None = None) -> list[dict]:
    """J and metrics of ``gains`` on each of ``cases`` (runs in ``workers`` threads).

    Parameters
    ----------
    kind : str
        Controller kind.
    gains : dict of str to float
        ``[controller]`` keys.
    cases : sequence of Case
        Scenarios.
    duration, dt : float
        Run length and RK4 step (s).
    objective : Objective, optional
        Weights of J.
    workers : int, optional
        Threads (default :func:`auvtrack.batch.runner.default_workers`).

    Returns
    -------
    list of dict
        One record per case (see :func:`run_cost`) with its ``case`` name.
    """
    with stoppable_pool(_threads(workers)) as pool:
        out = list(pool.map(lambda c: run_cost(c, kind, gains, duration, dt, objective)[1], cases))
    for c, rec in zip(cases, out):
        rec["case"] = c.name
    return out


# --------------------------------------------------------------------------- presets and report

def preset_toml(result: TuneResult, budget: Budget, objective: Objective) -> str:
    """TOML text of a gain preset for ``auvtrack/data/gains/<kind>_tuned.toml``.

    Parameters
    ----------
    result : TuneResult
        Output of :func:`tune`.
    budget : Budget
        The budget used (recorded as provenance).
    objective : Objective
        The objective used (recorded as provenance).

    Returns
    -------
    str
        The file's text (kind, description, ``[gains]``, ``[provenance]``).
    """
    space = SPACES[result.kind]
    lines = [
        f"# Gain preset \"{result.kind}_tuned\": written by `auvtrack study tuning` (auvtrack/studies/tuning.py).",
        "# Procedure, objective, scenarios and results: docs/tuning.md.  Use it with",
        f"#   [controller]  kind = \"{result.kind}\"  preset = \"{result.kind}_tuned\"",
        "# (keys given explicitly next to `preset` override these gains).",
        "",
        f"kind = \"{result.kind}\"",
        f"description = \"{result.kind} gains tuned by Optuna TPE on Section 4 + 2 variations "
        f"(seed {budget.seed}, {result.nfev} evaluations)\"",
        "",
        "[gains]",
        *[f"{k} = {v!r}" for k, v in result.gains.items()],
        "",
        "[provenance]",
        "study = \"auvtrack study tuning\"",
        f"optimiser = \"optuna {_optuna_version()} TPESampler (seeded; trial 0 = package defaults; batches of "
        f"{budget.de_popsize(len(space.names)) * len(space.names)} asked together)\"",
        f"seed = {budget.seed}",
        f"popsize = {budget.de_popsize(len(space.names))}",
        f"population = {budget.de_popsize(len(space.names)) * len(space.names)}",
        f"maxiter = {budget.maxiter}",
        f"evaluations = {result.nfev}",
        f"train_cases = {json.dumps([c.name for c in TRAIN_CASES[: budget.n_train]])}",
        f"train_duration_s = {budget.duration!r}",
        f"dt_s = {budget.dt!r}",
        f"objective = \"{objective.w_itae:g} * sum ITAE + {objective.w_energy:g} * sum energy_tau + "
        f"{objective.w_tv:g} * sum tv_tau; failure {objective.penalty:g} * (2 - t_fail / duration)\"",
        f"tuned = {json.dumps(list(space.names))}",
        f"bounds = {json.dumps([list(b) for b in space.bounds])}",
        f"train_objective = {result.train_objective:.6g}",
        f"default_train_objective = {result.start_objective:.6g}",
        "",
    ]
    return "\n".join(lines)


def _optuna_version() -> str:
    import optuna

    return optuna.__version__


def _fmt(x: float) -> str:
    return "inf" if not math.isfinite(x) else f"{x:.4g}"


def _report(out: Path, results: dict[str, TuneResult], evals: dict, budget: Budget, objective: Objective,
            quick: bool, heldout: Sequence[Case]) -> Report:
    rep = Report(out, "Fair tuning of the controllers")
    if quick:
        rep.paragraph("**Quick mode** (CI smoke test): tiny budget, short runs; the numbers are not meaningful.")
    rep.paragraph(f"Optimiser: Optuna TPE, seed {budget.seed}, batches of {budget.population} candidates, "
                  f"{budget.maxiter + 1} batches, the package defaults as first candidate. "
                  f"Training: {', '.join(c.name for c in TRAIN_CASES[: budget.n_train])} "
                  f"({budget.duration:g} s, dt {budget.dt:g} s). Held-out: "
                  f"{', '.join(c.name for c in heldout)} ({budget.heldout_duration:g} s).")
    rep.paragraph(f"Objective per run: {objective.w_itae:g} ΣITAE + {objective.w_energy:g} Σ∫τ²dt + "
                  f"{objective.w_tv:g} ΣTV(τ)/s; failure {objective.penalty:g}(2 − t_fail/T). Mean over scenarios.")
    rep.heading("Tuned gains")
    rows = []
    for kind, r in results.items():
        g = ", ".join(f"{k} {r.start_gains[k]:.4g} → {v:.4g}" for k, v in r.gains.items())
        rows.append([kind, g, r.nfev, f"{r.wall_s:.1f}"])
    rep.table(["controller", "gains (default → tuned)", "evaluations", "wall (s)"], rows)
    rep.heading("Objective (mean J; lower is better)")
    rep.table(["controller", "gains", "training", "held-out", *evals["columns"]],
              [[row["kind"], row["gains"], _fmt(row["train"]), _fmt(row["heldout"]), *(_fmt(x) for x in row["per_case"])]
               for row in evals["rows"]])
    rep.heading("Held-out runs in detail")
    rows = []
    for row in evals["rows"]:
        for rec in row["records"]:
            m = rec["metrics"]
            st = rec["status"] if rec["failure"] is None else \
                f"failed ({rec['failure']['cause']} at {rec['failure']['time']:.3g} s)"
            rows.append([row["kind"], row["gains"], rec["case"], st, _fmt(rec["J"]),
                         "/".join(_fmt(m[f"itae_{a}"]) for a in AXES), "/".join(_fmt(m[f"rmse_{a}"]) for a in AXES),
                         "/".join(_fmt(m[f"tv_tau_{j}"]) for j in INPUTS)])
    rep.table(["controller", "gains", "case", "status", "J", "ITAE x/y/z", "RMSE x/y/z (m)", "TV τ u/q/r"], rows)
    return rep


def run(out: Path, *, quick: bool = False, progress: bool = False) -> Path:
    """Tune every controller of :data:`SPACES`, evaluate on held-out scenarios, write presets and a report.

    Parameters
    ----------
    out : pathlib.Path
        Output folder (created): ``report.md``, ``report.html``, ``results.json`` and one
        ``<kind>_tuned.toml`` per controller (copy them to ``auvtrack/data/gains/`` to update the
        presets).
    quick : bool, optional
        CI smoke test: about 16 evaluations of one 4 s scenario per controller.
    progress : bool, optional
        Print one line per batch.

    Returns
    -------
    pathlib.Path
        The report ``out/report.md``.
    """
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    budget, objective = (QUICK if quick else FULL), Objective()
    say = print if progress else None
    compile_first([(kind, "5dof") for kind in SPACES], progress=progress)
    results = {kind: tune(kind, budget, objective, progress=say) for kind in SPACES}
    heldout = HELDOUT_CASES[:1] if quick else HELDOUT_CASES
    train = TRAIN_CASES[: budget.n_train]
    columns = [c.name for c in heldout] + ([] if quick else [f"{PAPER_CASE.name}"])
    rows = []
    for kind, r in results.items():
        for label, gains in (("default", r.start_gains), ("tuned", r.gains)):
            recs = evaluate(kind, gains, heldout, budget.heldout_duration, budget.dt, objective)
            per_case = [rec["J"] for rec in recs]
            if not quick:
                paper = evaluate(kind, gains, [PAPER_CASE], 100.0, budget.dt, objective)
                recs += paper
                per_case.append(paper[0]["J"])
            train_j = r.start_objective if label == "default" else r.train_objective
            rows.append({"kind": kind, "gains": label, "train": train_j,
                         "heldout": float(np.mean([rec["J"] for rec in recs[: len(heldout)]])),
                         "per_case": per_case, "records": recs, "values": gains})
    evals = {"columns": columns, "rows": rows}
    for kind, r in results.items():
        (out / f"{kind}_tuned.toml").write_text(preset_toml(r, budget, objective))
    write_json(out / "results.json", (
        {"budget": asdict(budget), "objective": asdict(objective), "quick": quick,
         "train_cases": [asdict(c) for c in train], "heldout_cases": [asdict(c) for c in heldout],
         "results": {k: asdict(r) for k, r in results.items()}, "evaluation": rows}))
    return _report(out, results, evals, budget, objective, quick, heldout).write()


STUDY = StudySpec("tuning", run, "fair tuning of every controller: same optimiser, budget, objective; "
                  "held-out evaluation; writes gain presets")
