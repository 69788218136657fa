"""``auvtrack/Track-v0``: one benchmark suite cell (task x tier) as a Gymnasium environment.

An episode is the suite's run of seed index ``s`` (``reset(seed=s)``; without a seed, an index
drawn from the environment's generator): the same start, tier draws, disturbances and noise as
``auvtrack compare`` with that seed index, flown by the agent's actions instead of a controller.

* **Control**: every ``substeps`` RK4 steps of the suite's ``sim.dt`` (default 10 x 2 ms = 50 Hz),
  zero-order hold, integrated in compiled code (:mod:`auvtrack.gym.stepping`); the episode's
  ``sim.control_rate`` is set to that rate (the digital tier's 100 Hz is replaced by it).
* **Actions**: ``Box(-1, 1, (3,))``.  ``action="tau"``: tau = scale * a with scale the
  actuator limit ``actuator.tau_max`` where finite, else the vehicle preset's actuator reach
  (N, N m, N m); ``action="actuators"`` (6-DOF tiers): (rpm, stern plane, rudder) = scale * a with
  scale the plant's actuator limits.
* **Observations**: :mod:`auvtrack.control.policy_observation` (the function the ``policy`` law
  uses), a Box with its clip bounds.
* **Reward**: minus the increment over the step of the episode's cost, built from the benchmark's
  metric sums and the suite's ``[run_score]`` (weights w, scales s, cap): every criterion c the run
  score weighs costs w_c t_c^2 when it is an RMS metric (:data:`SQUARED`: the squares are sums over
  time) and w_c t_c otherwise, with t_c = min(m_c / s_c, cap) the run score's term
  (:func:`~auvtrack.benchmark.scoring.run_score_terms`) and m_c the benchmark's metric of the episode
  so far with the means taken over the episode's duration T (:func:`~auvtrack.gym.stepping.episode_cost`):
  at the end of a completed episode m_c is the run's metric.  A failure costs one more than the sum of
  the caps, so a failed episode returns less than any completed one.  ``terminated``: the engine's failure causes;
  ``truncated``: the task's duration reached.  ``info["metrics"]`` at the end: the run's benchmark
  metrics (:func:`auvtrack.metrics.metrics_finalize`), ``info["status"]``, ``info["seed_index"]``.
"""
from __future__ import annotations

import json
import math
import sys
import time
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np

from ..benchmark.suite import Suite, load_suite
from ..control.policy_observation import OBS, OBS_BOUND
from ..engine.loop import CAUSES, SI, Stacked
from ..metrics import metrics_finalize
from ..plant.contract import SF
from ..scenario import load_scenario
from ..simulation.pipeline import Prepared, prepare
from ..user_modules import load_module
from ..vehicle.presets import get_preset
from .replay import GAINS
from .stepping import COST_TERMS, PARALLEL_FROM, Carry, new_carry, step_module

ACTIONS = {"tau": "auvtrack.gym.replay", "actuators": "auvtrack.gym.replay_actuators"}
"""Action modes -> the replay law that applies them."""


def suite_of(suite: str | Path | Suite) -> Suite:
    """A loaded suite from its name, path or itself."""
    return suite if isinstance(suite, Suite) else load_suite(suite, check=False)


def episode_scenario(suite: Suite, task: str, tier: str, index: int, *, action: str = "tau", substeps: int = 10,
                     duration: float | None = None, scale=(1.0, 1.0, 1.0), actions=()) -> Any:
    """The validated scenario of one episode (suite run ``index`` flown by the replay law).

    Parameters
    ----------
    suite : Suite
        The suite.
    task, tier : str
        The cell.
    index : int
        Seed index.
    action : str, optional
        ``"tau"`` or ``"actuators"``.
    substeps : int, optional
        RK4 steps per control step.
    duration : float, optional
        Episode length (s); default the task's.
    scale : sequence of 3 float, optional
        Action scale packed into the replay law.
    actions : sequence of 3-tuples, optional
        Actions to replay (an engine run of them: tests).

    Returns
    -------
    Scenario
        The scenario.
    """
    if action not in ACTIONS:
        raise ValueError(f"action: must be one of {', '.join(ACTIONS)} (got {action!r})")
    if not (isinstance(substeps, int) and substeps >= 1):
        raise ValueError(f"substeps: must be an integer >= 1 (got {substeps!r})")
    raw, overrides, _ = suite.conditions(task, tier, index)
    dt = float(overrides.get("sim.dt", 0.002))
    dur = float(duration if duration is not None else raw["sim"]["duration"])
    samples = int(math.floor(dur / (substeps * dt) + 1e-9)) + 1
    raw = {"name": f"gym-{suite.name}-{task}-{tier}-{index}", **raw,
           "controller": {"kind": "plugin", "module": ACTIONS[action],
                          "params": {"scale": list(scale), "samples": samples, "actions": [list(a) for a in actions]}}}
    raw["sim"] = {**raw["sim"], "duration": dur}
    overrides = {**overrides, "sim.control_rate": 1.0 / (substeps * dt)}
    return load_scenario(raw, overrides)


def action_scale(prep: Prepared, action: str) -> np.ndarray:
    """The action scale of an episode (see the module docstring).

    Parameters
    ----------
    prep : Prepared
        The episode's prepared run.
    action : str
        ``"tau"`` or ``"actuators"``.

    Returns
    -------
    numpy.ndarray
        (3,) positive scale.
    """
    sc = prep.scenario
    if action == "actuators":
        module = load_module(prep.key.plant)
        _, hi, _ = module.feedback(prep.plant.x0, np.zeros(len(getattr(module, "COMMAND"))), prep.plant.pp)
        return np.array([float(v) for v in hi])
    tau_max = np.array([float(v) for v in sc.actuator.tau_max])
    reach = get_preset(sc.vehicle.preset, u0=getattr(sc.vehicle, "u0", None)).reach
    if reach is None and not np.all(np.isfinite(tau_max)):
        raise ValueError("actuator.tau_max: must be finite on every axis for vehicle presets without an actuator reach")
    out = np.where(np.isfinite(tau_max), tau_max, np.asarray(reach if reach is not None else tau_max, dtype=float))
    return out


SQUARED = ("rmse", "xtrack_rmse", "vtrack_rmse", "along_rmse")
"""Cost terms that are an RMS metric m: charged as w min((m/s)^2, cap^2) = w t^2 (t the run score's term), m^2 =
the accumulated sum over the episode's duration T, so that the cost grows with the time integral of the error."""
PER_SECOND = ("tv", "act_rate_u", "act_rate_q", "act_rate_r")
"""Cost terms whose metric is a total variation per second: the accumulated variation over T."""


def reward_weights(suite: Suite) -> tuple[tuple[float, ...], tuple[float, ...], float]:
    """The reward's weights, caps and failure penalty from the suite's ``[run_score]`` (module docstring).

    Every criterion the run score weighs is a cost term (:data:`~auvtrack.gym.stepping.COST_TERMS`,
    named by the criterion) with the run score's weight w, scale s and cap.

    Parameters
    ----------
    suite : Suite
        The suite.

    Returns
    -------
    (tuple, tuple, float)
        Per cost term: k = w / s^2 (:data:`SQUARED`) or w / s, still to be divided by the duration for
        the :data:`SQUARED` and :data:`PER_SECOND` terms; the cap w cap^2 (:data:`SQUARED`) or w cap;
        and the penalty, one more than the sum of the caps.  A suite without a run score charges the
        virtual point's error alone (w = s = 1).

    Raises
    ------
    ValueError
        The run score weighs a criterion that is not a cost term.
    """
    rs = suite.file.run_score
    if not any(w > 0 for w in rs.weights.values()):
        rs = rs.model_copy(update={"weights": {"rmse": 1.0}, "scales": {"rmse": 1.0}})
    missing = [c for c, w in rs.weights.items() if w > 0 and c not in COST_TERMS]
    if missing:
        raise ValueError(f"run_score.weights: {', '.join(missing)}: not a reward term of the environment "
                         f"(those are {', '.join(COST_TERMS)})")
    k, caps = [], []
    for term in COST_TERMS:
        w, s = rs.weights.get(term, 0.0), rs.scales.get(term, 1.0)
        square = term in SQUARED
        k.append(w / s ** 2 if square else w / s)
        caps.append(w * rs.cap ** 2 if square else w * rs.cap)
    return tuple(k), tuple(caps), 1.0 + sum(caps)


class TrackEnv(gym.Env):
    """One suite cell as an environment (module docstring).

    Parameters
    ----------
    suite : str, Path or Suite, optional
        A shipped suite's name, a suite file, or a loaded suite.
    task, tier : str, optional
        The cell (default: the suite's first task and tier).
    action : str, optional
        ``"tau"`` (default) or ``"actuators"`` (6-DOF tiers).
    substeps : int, optional
        RK4 steps per control step (default 10).
    duration : float, optional
        Episode length (s); default the task's duration.
    """

    metadata = {"render_modes": []}

    def __init__(self, suite: str | Path | Suite = "auv-track-v1", task: str | None = None, tier: str | None = None,
                 action: str = "tau", substeps: int = 10, duration: float | None = None) -> None:
        self.suite = suite_of(suite)
        self.task = task or self.suite.tasks[0]
        self.tier = tier or self.suite.tiers[0]
        if self.task not in self.suite.tasks:
            raise ValueError(f"task: must be one of {', '.join(self.suite.tasks)} (got {self.task!r})")
        if self.tier not in self.suite.tiers:
            raise ValueError(f"tier: must be one of {', '.join(self.suite.tiers)} (got {self.tier!r})")
        self.action_mode, self.substeps, self.duration = action, substeps, duration
        episode_scenario(self.suite, self.task, self.tier, 0, action=action, substeps=substeps, duration=duration)
        self.observation_space = gym.spaces.Box(-OBS_BOUND, OBS_BOUND, dtype=np.float64)
        self.action_space = gym.spaces.Box(-1.0, 1.0, (3,), dtype=np.float64)
        self._weights = reward_weights(self.suite)
        self.prep: Prepared | None = None
        self.seed_index = 0

    # ------------------------------------------------------------ episode set-up
    def _prepare(self, index: int) -> None:
        sc = episode_scenario(self.suite, self.task, self.tier, index, action=self.action_mode,
                              substeps=self.substeps, duration=self.duration)
        prep = prepare(sc)
        cp = prep.controller.cp.copy()
        cp[GAINS.scale:GAINS.scale + 3] = action_scale(prep, self.action_mode)
        self.prep, self.seed_index, self.scale = prep, index, cp[:3].copy()
        one = lambda a: np.ascontiguousarray(np.asarray(a)[None])  # noqa: E731
        self.ins = Stacked(one(prep.plant.pp), one(prep.plant.x0), one(cp), one(prep.controller.x0),
                           one(prep.controller.vp), one(prep.environment.rows), one(prep.environment.current),
                           one(prep.environment.noise), one(prep.ref_p), one(prep.settings.si), one(prep.settings.sf))
        module = load_module(prep.key.plant)
        self.carry: Carry = new_carry(1, prep.plant.x0.size, prep.controller.x0.size,
                                      len(getattr(module, "COMMAND")), OBS.size)
        self.carry.xp[0] = prep.plant.x0
        self.carry.xc[0] = prep.controller.x0
        duration = float(prep.scenario.sim.duration)
        k, caps, penalty = self._weights
        self.carry.rw[0] = (*(v / duration if term in SQUARED + PER_SECOND else v for term, v in zip(COST_TERMS, k)),
                            *caps, penalty)
        self.kernels = step_module(prep.key)
        self.kernels.observe_all(self.ins, self.carry, OBS_BOUND)

    @property
    def n_steps(self) -> int:
        """RK4 steps of the episode."""
        return int(self.ins.si[0, SI.n_steps])

    @property
    def ctrl_every(self) -> int:
        """RK4 steps per control step."""
        return int(self.ins.si[0, SI.ctrl_every])

    def reset(self, *, seed: int | None = None, options: dict | None = None):
        """Start the suite run of seed index ``seed`` (or one drawn from the environment's generator).

        Parameters
        ----------
        seed : int, optional
            The suite seed index.
        options : dict, optional
            Unused.

        Returns
        -------
        (numpy.ndarray, dict)
            The first observation and ``{"seed_index": ...}``.
        """
        super().reset(seed=seed)
        index = int(seed) if seed is not None else int(self.np_random.integers(0, 2**31 - 1))
        self._prepare(index)
        return self.carry.obs[0].copy(), {"seed_index": index}

    def step(self, action):
        """Hold ``action`` (clipped to [-1, 1]) for one control period.

        Parameters
        ----------
        action : array_like
            (3,) normalised command.

        Returns
        -------
        (numpy.ndarray, float, bool, bool, dict)
            Observation, reward, terminated, truncated, info (metrics at the episode's end).
        """
        if self.prep is None:
            raise RuntimeError("call reset() before step()")
        a = np.clip(np.asarray(action, dtype=np.float64).reshape(3), -1.0, 1.0)
        c = self.carry
        row = int(c.ks[0, 0]) // self.ctrl_every
        base = GAINS.table + 3 * min(row, int(self.ins.cp[0, GAINS.n]) - 1)
        self.ins.cp[0, base:base + 3] = a
        self.kernels.step_serial(self.ins, c, OBS_BOUND)
        cause = int(c.cause[0])
        terminated = cause != 0
        truncated = (not terminated) and int(c.ks[0, 0]) >= self.n_steps
        info: dict[str, Any] = {"seed_index": self.seed_index}
        if terminated or truncated:
            info.update(self.episode_info())
        return c.obs[0].copy(), float(c.reward[0]), terminated, truncated, info

    def episode_info(self) -> dict[str, Any]:
        """The benchmark metrics and status of the episode so far.

        Returns
        -------
        dict
            ``metrics``, ``status`` (``"ok"`` or a failure cause's name) and ``t``.
        """
        c = self.carry
        t = int(c.ks[0, 0]) * float(self.ins.sf[0, SF.dt])
        t0, t1 = self.prep.scenario.metrics.window
        cause = int(c.cause[0])
        status = "ok" if cause == 0 else CAUSES.get(cause, ("controller", ""))[0]
        return {"metrics": metrics_finalize(c.acc[0].copy(), t0, min(t1, t)), "status": status, "t": t}


def _example_step_arguments() -> tuple:
    """Arguments of a step module's functions with the types every environment passes (C-contiguous, writeable)."""
    f2, f3 = np.zeros((1, 1)), np.zeros((1, 1, 1))
    ins = Stacked(f2, f2, f2, f2, f2, f3, f3, f3, f2, np.zeros((1, SI.size), np.int64), np.zeros((1, SF.size)))
    return ins, new_carry(1, 1, 1, 1, OBS.size), OBS_BOUND


def _step_marker(key, part: str) -> Path:
    from ..jit import cache_dir

    return cache_dir() / "kernels" / f"gym_{key.name}.{part}.json"


def compile_steps(envs: Iterable, *, index: int = 0, progress: bool = False,
                  notice: Callable[[str], None] | None = None) -> list[str]:
    """Compile (or load) the compiled step of environments before their first episode.

    The step functions of each (replay law, plant) pair (:func:`auvtrack.gym.stepping.step_module`)
    compile on first use, about as long as a kernel; this compiles the ones ``envs`` call (a
    vector environment of :data:`~auvtrack.gym.stepping.PARALLEL_FROM` envs or more also its
    multithreaded step) with the "compiling kernels (first run only, about N s)" notice when any
    is not cached yet.  It runs in a thread (:func:`auvtrack.simulation.compiling.interruptible`):
    Ctrl-C or SIGTERM stops the wait at once.

    Parameters
    ----------
    envs : iterable of TrackEnv or TrackVectorEnv
        The environments.
    index : int, optional
        The seed index whose episode names the plant (a tier's ``cycle`` may vary it).
    progress : bool, optional
        A progress bar over the functions compiled.
    notice : callable, optional
        Receives the notice (default: printed to standard error).

    Returns
    -------
    list of str
        The functions compiled now, ``"<pair>: <function>"`` (empty when every one was cached).
    """
    from ..simulation.compiling import interruptible

    return interruptible(lambda: _compile_steps(list(envs), index, progress, notice))


def _compile_steps(envs: list, index: int, progress: bool, notice: Callable[[str], None] | None) -> list[str]:
    import numba

    from ..engine.kernels import compile_estimate

    todo: dict[Any, list[str]] = {}
    for env in envs:
        one = getattr(env, "one", env)
        parts = ["observe_all", "step_serial"] + (["step_all"] if getattr(env, "num_envs", 1) >= PARALLEL_FROM else [])
        key = prepare(episode_scenario(one.suite, one.task, one.tier, index, action=one.action_mode,
                                       substeps=one.substeps, duration=one.duration)).key
        for part in parts:
            if part not in todo.get(key, []) and not _step_marker(key, part).is_file():
                todo.setdefault(key, []).append(part)
    if not todo:
        return []
    say = notice or (lambda text: print(text, file=sys.stderr, flush=True))
    heavy = sum(p != "observe_all" for parts in todo.values() for p in parts)
    names = ", ".join(f"{key.label or key.name} environment step" for key in todo)
    say(f"compiling kernels (first run only, about {compile_estimate() * max(heavy, 1):.0f} s): {names}")
    total = sum(len(parts) for parts in todo.values())
    bar = None
    if progress:
        from tqdm import tqdm

        bar = tqdm(total=total, desc="compiling", unit="kernel", leave=False)
    sig = tuple(numba.typeof(a) for a in _example_step_arguments())
    done = []
    try:
        for key, parts in todo.items():
            module = step_module(key)
            for part in parts:
                t0 = time.perf_counter()
                getattr(module, part).compile(sig)
                marker = _step_marker(key, part)
                marker.parent.mkdir(parents=True, exist_ok=True)
                marker.write_text(json.dumps({"kernel": f"gym_{key.name}", "function": part,
                                              "seconds": round(time.perf_counter() - t0, 2)}))
                done.append(f"{key.label or key.name}: {part}")
                if bar is not None:
                    bar.update(1)
    finally:
        if bar is not None:
            bar.close()
    return done
