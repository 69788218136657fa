"""The run plan: every size a scenario implies, computed before anything is allocated or run.

:func:`plan_run` is pure arithmetic on a validated :class:`~auvtrack.scenario.Scenario`: RK4 steps,
logged rows, control samples, noise and current table rows and an estimate of the peak memory of
the run's arrays.  Each number that becomes an integer is range-checked against the scenario's
``[limits]`` *before* it is converted, so an absurd grid (``dt = 1e-12``, ``duration = 1e300``)
is one line naming the field and the limit, never an endless run, a NumPy allocation traceback
or an ``OverflowError``.  :func:`auvtrack.simulation.pipeline.prepare` calls it, so ``auvtrack check``,
``auvtrack run``, batches and sweeps all refuse the same scenarios with the same message.

The limits and how to raise them are documented in ``docs/scenarios.md`` (``[limits]``).
"""
from __future__ import annotations

import math
from dataclasses import asdict, dataclass

from .errors import ScenarioError
from .schema import Scenario, SimSection

__all__ = ["RunPlan", "plan_run", "check_state_memory", "STATE_COPIES", "LOG_COPIES", "NOISE_BYTES_PER_ROW", "CURRENT_BYTES_PER_ROW",
           "CSV_BLOCK_ROWS", "CSV_BYTES_PER_VALUE"]

FLOAT = 8  # bytes
LOG_COPIES = 3  # the engine's log, the per-channel copies, the Result's private copies
NOISE_COLS = 10
NOISE_BYTES_PER_ROW = 2 * NOISE_COLS * FLOAT  # the normal draws and the scaled table
CURRENT_BYTES_PER_ROW = 128  # sampling transients plus the stacked table (measured peak 104, docs)
STATE_COPIES = 8  # the bundle's start, the running state, the state after a step, the stage state, 4 RK4 slopes
CSV_BLOCK_ROWS = 2000  # Result.save writes the CSV in blocks of this many rows
CSV_BYTES_PER_VALUE = 160  # Python float + its repr string while a block is formatted
_DEFAULT_DT = SimSection.model_fields["dt"].default


@dataclass(frozen=True)
class RunPlan:
    """Sizes of one run, all checked against the scenario's ``[limits]``.

    Attributes
    ----------
    n_steps : int
        RK4 steps, ``duration / dt``.
    log_every, log_rows : int
        Steps between logged rows; rows logged (``n_steps / log_every + 1``, the last at t = duration).
    control_every, control_samples : int
        Steps between controller samples and their number (0 and 0 for continuous control).
    noise_rows : int
        Rows of the sensor-noise table (one per control sample; 0 without noise).
    current_rows : tuple of int
        Samples of each ``current`` disturbance, in the order of the ``[[disturbance]]`` list.
    n_channels : int
        Logged channels.
    log_bytes, table_bytes : int
        Estimated peak bytes of the log (with its copies and the CSV writer's block) and of the
        noise and current tables (with their generation transients).
    """

    n_steps: int
    log_every: int
    log_rows: int
    control_every: int
    control_samples: int
    noise_rows: int
    current_rows: tuple[int, ...]
    n_channels: int
    log_bytes: int
    table_bytes: int

    @property
    def memory_bytes(self) -> int:
        """Estimated peak bytes of the run's arrays with a trajectory (``auvtrack run``)."""
        return self.log_bytes + self.table_bytes

    def to_dict(self) -> dict:
        """The plan as a JSON-serialisable dict (recorded in ``run.json`` under ``meta.plan``)."""
        d = asdict(self)
        d["current_rows"] = list(self.current_rows)
        d["memory_bytes"] = self.memory_bytes
        return d


def _raise_hint(key: str) -> str:
    return f"(raise it deliberately with --set limits.{key}=N or a [limits] table)"


def _over(path: str, what: str, key: str, limit: int) -> ScenarioError:
    return ScenarioError(f"{path}: {what}, more than limits.{key} = {limit} {_raise_hint(key)}", path)


def _count(value: float, step: float) -> float:
    """``value / step`` as a float (inf when it overflows); the caller bounds it before rounding."""
    q = value / step
    return q if math.isfinite(q) else math.inf


def plan_run(scenario: Scenario, n_channels: int) -> RunPlan:
    """Compute and check the sizes of a run of ``scenario``.

    Parameters
    ----------
    scenario : Scenario
        A validated scenario.
    n_channels : int
        Number of logged channels (the engine's base channels, the controller's extra channels
        and chi).

    Returns
    -------
    RunPlan
        The sizes, each within the scenario's ``[limits]``.

    Raises
    ------
    ScenarioError
        One line naming the field that sets the size (``sim.dt``, ``sim.duration``,
        ``sim.log_dt``, ``sim.control_rate``, ``disturbance.<i>.sample_dt``), the size and the
        limit it exceeds.
    """
    sc, lim = scenario, scenario.limits
    sim = sc.sim
    steps = _count(sim.duration, sim.dt)
    if steps > lim.max_steps * (1 + 1e-9):
        # blame the duration when it is too long even at the default step, else the step
        alone = sim.duration / _DEFAULT_DT
        path = "sim.duration" if alone > lim.max_steps else "sim.dt"
        raise _over(path, f"sim.duration / sim.dt = {sim.duration:g} s / {sim.dt:g} s gives {steps:.4g} RK4 steps",
                    "max_steps", lim.max_steps)
    n_steps = sim.n_steps
    log_every = sim.log_every
    log_rows = n_steps // log_every + 1
    if log_rows > lim.max_log_rows:
        raise _over("sim.log_dt", f"logging every {sim.log_dt:g} s over {sim.duration:g} s gives {log_rows} rows",
                    "max_log_rows", lim.max_log_rows)
    control_every = sim.control_every
    control_samples = n_steps // control_every + 1 if control_every else 0
    noisy = any(s > 0 for s in (*sc.sensor.sigma_eta, *sc.sensor.sigma_nu))
    noise_rows = control_samples if noisy else 0
    if noise_rows > lim.max_table_rows:
        raise _over("sim.control_rate", f"{sim.control_rate:g} Hz over {sim.duration:g} s with sensor noise gives "
                    f"{noise_rows} noise rows", "max_table_rows", lim.max_table_rows)
    current_rows = []
    current_paths = []
    for i, spec in enumerate(sc.disturbance):
        if spec.get("kind") != "current":
            continue
        path = f"disturbance.{i}.sample_dt"
        n = _count(sim.duration, float(spec["sample_dt"])) + 1
        if n > lim.max_table_rows:
            raise _over(path, f"sampling the current every {spec['sample_dt']:g} s over {sim.duration:g} s gives "
                        f"{n:.4g} samples", "max_table_rows", lim.max_table_rows)
        current_rows.append(_current_samples(spec, sim.duration))
        current_paths.append(path)
    log_bytes = LOG_COPIES * FLOAT * log_rows * n_channels + min(log_rows, CSV_BLOCK_ROWS) * n_channels * CSV_BYTES_PER_VALUE
    parts = {"sim.log_dt": log_bytes, "sim.control_rate": NOISE_BYTES_PER_ROW * noise_rows}
    for path, n in zip(current_paths, current_rows):
        parts[path] = CURRENT_BYTES_PER_ROW * n
    plan = RunPlan(n_steps, log_every, log_rows, control_every, control_samples, noise_rows, tuple(current_rows),
                   n_channels, log_bytes, sum(parts.values()) - log_bytes)
    limit_bytes = lim.max_memory_mb * 2 ** 20
    if plan.memory_bytes > limit_bytes:
        path = max(parts, key=parts.get)
        raise _over(path, f"the run's arrays need an estimated {plan.memory_bytes / 2 ** 20:.0f} MiB "
                    f"({parts[path] / 2 ** 20:.0f} MiB from this field)", "max_memory_mb", lim.max_memory_mb)
    return plan


def check_state_memory(scenario: Scenario, plan: RunPlan, state_floats: dict[str, int]) -> int:
    """Check the run's arrays with the plant's and the controller's states against ``max_memory_mb``.

    The state sizes are known only once the plant and the controller are set up (a plug-in
    chooses its own), so :func:`plan_run` cannot count them; :func:`~auvtrack.simulation.pipeline.prepare`
    calls this right after the set-up, before the engine makes its copies of the states.

    Parameters
    ----------
    scenario : Scenario
        The validated scenario (its ``[limits]``).
    plan : RunPlan
        Its plan (:func:`plan_run`).
    state_floats : dict of str to int
        Floats each piece holds for the run (state and packed parameters), keyed by the scenario
        section that chooses them (``"plant"``, ``"controller"``).

    Returns
    -------
    int
        Estimated bytes of the states with the engine's copies (:data:`STATE_COPIES` each, 8 bytes a float).

    Raises
    ------
    ScenarioError
        One line naming the section with the larger state, the estimate and ``limits.max_memory_mb``.
    """
    lim = scenario.limits
    parts = {k: STATE_COPIES * FLOAT * int(n) for k, n in state_floats.items()}
    state_bytes = sum(parts.values())
    if plan.memory_bytes + state_bytes > lim.max_memory_mb * 2 ** 20:
        path = max(parts, key=parts.get)
        raise _over(path, f"the run's arrays need an estimated {(plan.memory_bytes + state_bytes) / 2 ** 20:.0f} MiB "
                    f"({parts[path] / 2 ** 20:.0f} MiB for the {path}'s state and parameters, "
                    f"{state_floats[path]} floats kept in {STATE_COPIES} copies)", "max_memory_mb", lim.max_memory_mb)
    return state_bytes


def _current_samples(spec: dict, duration: float) -> int:
    """Exact sample count of a current, from the current model itself (one formula)."""
    from ..environment import build_disturbance

    return build_disturbance(dict(spec)).n_samples(duration)
