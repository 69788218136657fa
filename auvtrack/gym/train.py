"""Training a linear policy on the vector environment: augmented random search (ARS V2-t) or CMA-ES.

Mania, Guy and Recht (2018), "Simple random search of static linear policies is competitive for
reinforcement learning", NeurIPS, Algorithm 2, version V2-t: a linear policy
a = clip(M diag(sigma)^-1 (x - mu), -1, 1) on the observation x (:mod:`auvtrack.control.policy_observation`).
Each iteration j draws ``directions`` matrices delta_k with i.i.d. N(0, 1) entries, flies M_j +- nu delta_k
on the same training seeds (common random numbers), keeps the ``top`` directions by
max(r+, r-), and steps M_{j+1} = M_j + alpha / (top sigma_R) sum_k (r+_k - r-_k) delta_k, sigma_R the
standard deviation of the 2 top returns used; mu, sigma are the running mean and standard deviation
of every state met in training (Chan et al.'s pairwise update), used from the next iteration on.

CMA-ES (``method="cmaes"``; Hansen and Ostermeier 2001, the ``cma`` library): the entries of M are
searched by a (mu/mu_w, lambda) evolution strategy with lambda = 2 ``directions``, initial mean 0
and step size ``noise``; every candidate flies the iteration's seeds (common random numbers) and is
ranked by minus its return; the policy of an iteration is the distribution's mean.  The strategy's
normal draws come from ``SeedSequence([seed, j])`` (its ``randn`` option), so its state after
iteration j is a function of the returns told so far: a resumed training rebuilds it by telling the
checkpoint's returns again (no rollouts) and ends where the uninterrupted one does.

Seeds: every iteration draws ``seeds_per_iteration`` seed indices of the suite's ``training``
split (and flies every training task on the tier); the curve's held-out return flies the policy
M_j on every seed of the ``validation`` split.  A return is the episode's summed reward
(:mod:`auvtrack.gym.env`), averaged over seeds and tasks.  Iteration j's random numbers come from
``SeedSequence([seed, j])``, so a training stopped after any iteration and resumed from its checkpoint
ends exactly where the uninterrupted one does.
"""
from __future__ import annotations

import csv
import io
import json
import math
import platform
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np

from .._atomic import atomic_file, atomic_write
from ..benchmark.suite import Suite
from ..control.policy import save_policy
from ..control.policy_observation import OBS
from .env import compile_steps, reward_weights, suite_of
from .stepping import COST_TERMS
from .vector import TrackVectorEnv

__all__ = ["METHOD", "METHODS", "TrainConfig", "TrainResult", "command_line", "rollout", "train"]

METHODS = {"ars": "ARS V2-t (Mania, Guy and Recht 2018, Algorithm 2)",
           "cmaes": "CMA-ES (Hansen and Ostermeier 2001; the cma library)"}
"""Training methods: ``TrainConfig.method`` -> what the provenance records."""
METHOD = METHODS["ars"]
CHECKPOINT = "checkpoint.npz"
CURVE = ("iteration", "episodes", "env_steps", "train_return", "validation_return", "wall_s")
"""Columns of ``curve.csv`` (``validation_return`` empty where not evaluated)."""


@dataclass(frozen=True)
class TrainConfig:
    """What a training does (every field is in the policy's provenance).

    Attributes
    ----------
    suite : str
        A shipped suite's name or a suite file.
    tier : str
        The tier flown (default: the training split's first).
    tasks : tuple of str
        Tasks flown (default: the training split's).
    iterations : int
        ARS iterations (the budget).
    directions : int
        Random directions per iteration (N).
    top : int
        Directions kept (b <= N).
    step_size : float
        alpha.
    noise : float
        nu, the exploration standard deviation.
    seeds_per_iteration : int
        Training seed indices each direction flies per iteration.
    eval_every : int
        Iterations between held-out evaluations (the first and last are always evaluated).
    substeps : int
        RK4 steps per control step.
    duration : float or None
        Episode length (s); default the suite's task durations (``quick``: the suite's quick duration).
    quick : bool
        The suite's quick variant (short episodes).
    seed : int
        Seed of the random directions and the seed draws.
    method : str
        ``"ars"`` or ``"cmaes"`` (:data:`METHODS`).
    action : str
        ``"tau"`` or ``"actuators"`` (a 6-DOF tier; the policy file commands the actuators).
    """

    suite: str = "auv-track-v2"
    tier: str | None = None
    tasks: tuple[str, ...] = ()
    iterations: int = 50
    directions: int = 8
    top: int = 4
    step_size: float = 0.02
    noise: float = 0.03
    seeds_per_iteration: int = 2
    eval_every: int = 5
    substeps: int = 10
    duration: float | None = None
    quick: bool = False
    seed: int = 0
    method: str = "ars"
    action: str = "tau"

    def check(self) -> None:
        """Refuse out-of-range settings with one line naming the field.

        Raises
        ------
        ValueError
            The first bad field.
        """
        ints = {"iterations": (1, 100_000), "directions": (1, 1024), "top": (1, self.directions),
                "seeds_per_iteration": (1, 1024), "eval_every": (1, 100_000), "substeps": (1, 1000),
                "seed": (0, 2**31 - 1)}
        for name, (lo, hi) in ints.items():
            v = getattr(self, name)
            if not (isinstance(v, (int, np.integer)) and lo <= v <= hi):
                raise ValueError(f"{name}: must be an integer in [{lo}, {hi}] (got {v!r})")
        for name in ("step_size", "noise"):
            v = getattr(self, name)
            if not (isinstance(v, (int, float)) and math.isfinite(v) and 0 < v <= 10):
                raise ValueError(f"{name}: must be a number in (0, 10] (got {v!r})")
        if self.method not in METHODS:
            raise ValueError(f"method: must be one of {', '.join(METHODS)} (got {self.method!r})")
        if self.action not in ("tau", "actuators"):
            raise ValueError(f"action: must be one of tau, actuators (got {self.action!r})")
        if self.duration is not None and not (math.isfinite(self.duration) and self.duration > 0):
            raise ValueError(f"duration: must be a finite number > 0 s (got {self.duration!r})")


@dataclass
class TrainResult:
    """A finished (or resumed-and-finished) training.

    Attributes
    ----------
    M, mean, std : numpy.ndarray
        The policy matrix (3, OBS.size) and its observation normalisation.
    curve : list of dict
        One row per iteration (:data:`CURVE`), iteration 0 the initial policy.
    episodes, env_steps : int
        Training rollouts and environment steps so far (held-out ones not counted).
    wall_s : float
        Wall time of the training so far (s), over every resumed session.
    outputs : dict
        Files written.
    """

    M: np.ndarray
    mean: np.ndarray
    std: np.ndarray
    curve: list[dict] = field(default_factory=list)
    episodes: int = 0
    env_steps: int = 0
    wall_s: float = 0.0
    outputs: dict[str, Path] = field(default_factory=dict)


def _moments(batch: np.ndarray) -> tuple[int, np.ndarray | None, np.ndarray | None]:
    """(rows, mean, sum of squared deviations) of a batch of observations (None, None when empty)."""
    nb = batch.shape[0]
    if nb == 0:
        return 0, None, None
    mb = batch.mean(axis=0)
    return nb, mb, ((batch - mb) ** 2).sum(axis=0)


class _Moments(list):
    """The :func:`_moments` of every batch a rollout adds, in order (merged later into a :class:`_Stats`)."""

    def add(self, batch: np.ndarray) -> None:
        self.append(_moments(batch))


_REMOTE_ENVS: dict[tuple, TrackVectorEnv] = {}
"""Vector environments a Dask worker keeps between iterations, per (suite, quick, task, tier, n, settings)."""


def remote_rollout(key: tuple, seeds, Ms: np.ndarray, mean: np.ndarray, std: np.ndarray):
    """:func:`rollout` on a Dask worker: the env of ``key`` (made once per worker), the batches' moments recorded.

    Parameters
    ----------
    key : tuple
        (suite name or file, quick, task, tier, num_envs, action, substeps, duration).
    seeds, Ms, mean, std
        As :func:`rollout`.

    Returns
    -------
    (numpy.ndarray, int, list)
        Returns, environment steps, and the moments of the observation batches in order.
    """
    venv = _REMOTE_ENVS.get(key)
    if venv is None:
        suite, quick, task, tier, n, action, substeps, duration = key
        s = suite_of(suite)
        venv = TrackVectorEnv(n, s.quick_variant() if quick else s, task, tier, action=action, substeps=substeps,
                              duration=duration, autoreset="disabled")
        _REMOTE_ENVS[key] = venv
    moments = _Moments()
    r, steps = rollout(venv, seeds, Ms, mean, std, moments)
    return r, steps, list(moments)


class _Stats:
    """Running mean and sum of squared deviations of the observations (Chan et al. 1979, pairwise update)."""

    def __init__(self, n: float = 0.0, mean=None, m2=None) -> None:
        self.n = float(n)
        self.mean = np.zeros(OBS.size) if mean is None else np.asarray(mean, float).copy()
        self.m2 = np.zeros(OBS.size) if m2 is None else np.asarray(m2, float).copy()

    def add(self, batch: np.ndarray) -> None:
        """Add a batch of observations (rows)."""
        self.merge(*_moments(batch))

    def merge(self, nb: int, mb: np.ndarray | None, m2b: np.ndarray | None) -> None:
        """Add a batch given by its size, mean and sum of squared deviations (:func:`_moments`)."""
        if nb == 0:
            return
        n = self.n + nb
        delta = mb - self.mean
        self.mean = self.mean + delta * (nb / n)
        self.m2 = self.m2 + m2b + delta ** 2 * (self.n * nb / n)
        self.n = n

    def std(self) -> np.ndarray:
        """Standard deviation, 1 where a feature has not varied (its normalised value stays 0)."""
        if self.n < 2:
            return np.ones(OBS.size)
        sd = np.sqrt(self.m2 / (self.n - 1))
        return np.where(sd > 1e-8, sd, 1.0)


def rollout(venv: TrackVectorEnv, seeds, Ms: np.ndarray, mean: np.ndarray, std: np.ndarray,
            stats: _Stats | None = None) -> tuple[np.ndarray, int]:
    """Fly one episode per env, env i with policy ``Ms[i]`` from seed index ``seeds[i]``.

    Parameters
    ----------
    venv : TrackVectorEnv
        Built with ``autoreset="disabled"`` and ``len(seeds)`` envs.
    seeds : sequence of int
        Seed index per env.
    Ms : numpy.ndarray
        (num_envs, 3, OBS.size) policy matrices.
    mean, std : numpy.ndarray
        Observation normalisation.
    stats : _Stats, optional
        Updated with every observation the envs meet.

    Returns
    -------
    (numpy.ndarray, int)
        Return per env, environment steps flown.
    """
    obs, _ = venv.reset(seed=[int(s) for s in seeds])
    if stats is not None:
        stats.add(obs)
    ret = np.zeros(venv.num_envs)
    live = np.ones(venv.num_envs, bool)
    steps = 0
    while live.any():
        a = np.einsum("eij,ej->ei", Ms, (obs - mean) / std)
        obs, r, te, tr, _ = venv.step(a)
        ret += np.where(live, r, 0.0)
        steps += int(live.sum())
        if stats is not None:
            stats.add(obs[live])
        live &= ~(te | tr)
    return ret, steps


def _reward_terms(suite: Suite) -> dict:
    """The reward's cost terms with a weight (:func:`auvtrack.gym.env.reward_weights`): term -> (k, cap)."""
    k, caps, _ = reward_weights(suite)
    return {t: [kt, ct] for t, kt, ct in zip(COST_TERMS, k, caps) if kt > 0}


def _provenance(cfg: TrainConfig, suite: Suite, tier: str, tasks, res: TrainResult) -> dict:
    import gymnasium

    from .. import __version__

    tr, va = suite.split_seeds("training"), suite.split_seeds("validation")
    last = next((r["validation_return"] for r in reversed(res.curve) if r["validation_return"] != ""), None)
    return {"method": METHODS[cfg.method], "commands": cfg.action, "suite": suite.name, "suite_version": suite.file.version, "tier": tier,
            "tasks": list(tasks), "training_seeds": [tr.start, tr.stop], "validation_seeds": [va.start, va.stop],
            "config": asdict(cfg), "budget": {"iterations": len(res.curve) - 1, "episodes": res.episodes,
                                              "env_steps": res.env_steps, "rk4_steps": res.env_steps * cfg.substeps,
                                              "wall_s": round(res.wall_s, 1)},
            "validation_return": last, "command": command_line(cfg), "reward": _reward_terms(suite),
            "versions": {"auvtrack": __version__, "numpy": np.__version__, "gymnasium": gymnasium.__version__,
                         "python": platform.python_version()}}


class _Trainer:
    """The state of one training: environments, policy, statistics, curve."""

    def __init__(self, cfg: TrainConfig, notify: Callable[[str], None] | None = None, bar: bool = False) -> None:
        cfg.check()
        suite = suite_of(cfg.suite)
        self.suite = suite.quick_variant() if cfg.quick else suite
        cells = self.suite.split_cells("training")
        self.train_seeds = list(self.suite.split_seeds("training"))
        self.val_seeds = list(self.suite.split_seeds("validation"))
        tiers = list(dict.fromkeys(t for _, t in cells))
        self.tier = cfg.tier or tiers[0]
        if self.tier not in tiers:
            raise ValueError(f"tier: must be a tier of the training split: {', '.join(tiers)} (got {self.tier!r})")
        split_tasks = list(dict.fromkeys(k for k, t in cells if t == self.tier))
        self.tasks = list(cfg.tasks) or split_tasks
        for t in self.tasks:
            if t not in split_tasks:
                raise ValueError(f"tasks: {t!r} is not a task of the training split (allowed: {', '.join(split_tasks)})")
        self.cfg = cfg
        dur = {t: cfg.duration if cfg.duration is not None else (self.suite.duration(t) if cfg.quick else None)
               for t in self.tasks}
        n_train = 2 * cfg.directions * cfg.seeds_per_iteration
        self.train_envs = {t: TrackVectorEnv(n_train, self.suite, t, self.tier, action=cfg.action,
                                             substeps=cfg.substeps, duration=dur[t], autoreset="disabled")
                           for t in self.tasks}
        self.val_envs = {t: TrackVectorEnv(len(self.val_seeds), self.suite, t, self.tier, action=cfg.action,
                                           substeps=cfg.substeps, duration=dur[t], autoreset="disabled")
                         for t in self.tasks}
        self.client = None  # a Dask client: the training rollouts run on its workers
        self.es = None  # CMA-ES: the strategy (made by start_cmaes)
        self.fitness: list[np.ndarray] = []  # CMA-ES: the values told per iteration (checkpointed)
        compile_steps([*self.train_envs.values(), *self.val_envs.values()], index=self.train_seeds[0],
                      progress=bar, notice=notify)  # before the first episode, with the notice
        first = self.train_envs[self.tasks[0]].one
        first.reset(seed=self.train_seeds[0])
        self.scale = np.asarray(first.scale, float)  # the action scale the policy file records

    def validation_return(self, M: np.ndarray, mean: np.ndarray, std: np.ndarray) -> float:
        """Mean held-out return of policy M over the validation seeds and the tasks."""
        rets = []
        for venv in self.val_envs.values():
            r, _ = rollout(venv, self.val_seeds, np.repeat(M[None], venv.num_envs, 0), mean, std)
            rets.append(r)
        return float(np.mean(np.concatenate(rets)))

    def _draws(self, j: int) -> tuple[np.random.Generator, np.ndarray, np.ndarray | None]:
        """Iteration j's generator (after its draws), training seed indices and ARS directions."""
        cfg = self.cfg
        rng = np.random.default_rng(np.random.SeedSequence([cfg.seed, j]))
        delta = rng.standard_normal((cfg.directions, 3, OBS.size)) if cfg.method == "ars" else None
        seeds = rng.choice(self.train_seeds, size=cfg.seeds_per_iteration,
                           replace=cfg.seeds_per_iteration > len(self.train_seeds))
        return rng, seeds, delta

    def returns(self, Ms: np.ndarray, seeds: np.ndarray, stats: _Stats) -> tuple[np.ndarray, int]:
        """Mean return over the seeds and the tasks of each policy in ``Ms`` (stats updated), steps flown."""
        cfg = self.cfg
        mean, std = stats.mean.copy(), stats.std()
        n = Ms.shape[0]
        Ms = np.repeat(Ms, cfg.seeds_per_iteration, axis=0)  # env order: (policy, seed)
        env_seeds = np.tile(seeds, n)
        total, steps = np.zeros(n), 0
        if self.client is not None:  # one task per training task, merged in task order: the local numbers
            futures = [self.client.submit(remote_rollout, self.remote_key(t), env_seeds, Ms, mean, std, pure=False)
                       for t in self.train_envs]
            done = self.client.gather(futures)
        else:
            done = None
        for i, venv in enumerate(self.train_envs.values()):
            if done is None:
                r, k = rollout(venv, env_seeds, Ms, mean, std, stats)
            else:
                r, k, moments = done[i]
                for m in moments:
                    stats.merge(*m)
            total += r.reshape(n, cfg.seeds_per_iteration).mean(axis=1)
            steps += k
        return total / len(self.train_envs), steps

    def remote_key(self, task: str) -> tuple:
        """The :func:`remote_rollout` key of a training task's environments."""
        venv = self.train_envs[task]
        return (self.cfg.suite, self.cfg.quick, task, self.tier, venv.num_envs, self.cfg.action, self.cfg.substeps,
                venv.one.duration)

    def iteration(self, j: int, M: np.ndarray, stats: _Stats) -> tuple[np.ndarray, float, int, int]:
        """Iteration ``j`` from M (stats updated in place): new M, mean training return, episodes, steps."""
        cfg = self.cfg
        episodes = 2 * cfg.directions * cfg.seeds_per_iteration * len(self.train_envs)
        if cfg.method == "cmaes":
            M_new, r, steps = self.cmaes_iteration(j, stats)
            return M_new, r, episodes, steps
        _, seeds, delta = self._draws(j)
        signs = np.array([1.0, -1.0])  # policies in order (direction k, sign +/-)
        Ms = (M[None, None] + cfg.noise * signs[None, :, None, None] * delta[:, None]).reshape(-1, 3, OBS.size)
        ret, steps = self.returns(Ms, seeds, stats)
        r_pm = ret.reshape(cfg.directions, 2)
        order = np.argsort(-np.max(r_pm, axis=1), kind="stable")[:cfg.top]
        sigma_r = float(np.std(r_pm[order]))
        M_new = M.copy()
        if sigma_r > 0.0:
            M_new += cfg.step_size / (cfg.top * sigma_r) * np.einsum(
                "k,kij->ij", r_pm[order, 0] - r_pm[order, 1], delta[order])
        return M_new, float(r_pm.mean()), episodes, steps

    def start_cmaes(self, fitness: list[np.ndarray]) -> np.ndarray:
        """Make the CMA-ES strategy and tell it the checkpoint's values again; return its mean as M."""
        import cma

        cfg = self.cfg
        self._normal = None

        def randn(*shape):
            return self._normal.standard_normal(shape)

        self.es = cma.CMAEvolutionStrategy(np.zeros(3 * OBS.size), cfg.noise, {
            "popsize": 2 * cfg.directions, "randn": randn, "verbose": -9, "verb_log": 0, "verb_disp": 0,
            "seed": cfg.seed + 1, "tolfun": 0, "tolx": 0, "tolfunhist": 0, "tolstagnation": 10**9,
            "maxiter": 10**9, "CMA_mirrors": 0})
        self.fitness = []
        for j, f in enumerate(fitness):
            self._normal = self._draws(j)[0]
            self.es.tell(self.es.ask(), list(f))
            self.fitness.append(np.asarray(f, float))
        return np.asarray(self.es.mean, float).reshape(3, OBS.size).copy()

    def cmaes_iteration(self, j: int, stats: _Stats) -> tuple[np.ndarray, float, int]:
        """CMA-ES iteration j: ask lambda candidates, fly them, tell minus their returns."""
        rng, seeds, _ = self._draws(j)
        self._normal = rng
        X = self.es.ask()
        ret, steps = self.returns(np.asarray(X, float).reshape(-1, 3, OBS.size), seeds, stats)
        f = -ret
        self.es.tell(X, list(f))
        self.fitness.append(f)
        return np.asarray(self.es.mean, float).reshape(3, OBS.size).copy(), float(ret.mean()), steps


def _config_key(cfg: TrainConfig) -> dict:
    """The settings a checkpoint must share with a resumed training (all but the budget)."""
    d = asdict(cfg)
    d.pop("iterations")
    d["tasks"] = list(d["tasks"])
    return d


def _save_checkpoint(path: Path, cfg: TrainConfig, j: int, M: np.ndarray, stats: _Stats, res: TrainResult,
                     fitness: list[np.ndarray]) -> None:
    buf = io.BytesIO()
    told = np.array(fitness, float) if fitness else np.zeros((0, 0))
    np.savez(buf, M=M, n=np.array(stats.n), mean=stats.mean, m2=stats.m2, iteration=np.array(j), fitness=told,
             config=np.array(json.dumps(_config_key(cfg))), curve=np.array(json.dumps(res.curve)),
             counters=np.array([res.episodes, res.env_steps]), wall_s=np.array(res.wall_s))
    atomic_write(path, buf.getvalue())


def _load_checkpoint(path: Path, cfg: TrainConfig):
    with np.load(path, allow_pickle=False) as z:
        saved = {"method": "ars", "action": "tau", **json.loads(str(z["config"]))}  # a checkpoint from before both
        if saved != _config_key(cfg):
            diff = sorted(k for k in saved if saved.get(k) != _config_key(cfg).get(k))
            raise ValueError(f"--out: {path.parent} holds a training with other settings ({', '.join(diff)}); "
                             "use another folder or the same settings")
        res = TrainResult(z["M"].copy(), z["mean"].copy(), np.ones(OBS.size), json.loads(str(z["curve"])),
                          int(z["counters"][0]), int(z["counters"][1]), float(z["wall_s"]))
        fitness = [row.copy() for row in z["fitness"]] if "fitness" in z.files else []
        return int(z["iteration"]), res.M, _Stats(float(z["n"]), z["mean"], z["m2"]), res, fitness


def _write_curve(out: Path, curve: list[dict]) -> tuple[Path, Path | None]:
    text = io.StringIO()
    w = csv.DictWriter(text, fieldnames=CURVE, lineterminator="\n")
    w.writeheader()
    w.writerows(curve)
    atomic_write(out / "curve.csv", text.getvalue())
    return out / "curve.csv", _plot_curve(out / "curve.png", curve)


def _plot_curve(path: Path, curve: list[dict]) -> Path | None:
    """The learning curve (training and held-out return against environment steps)."""
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:  # the figure is optional; the CSV holds the curve
        return None
    fig, ax = plt.subplots(figsize=(6, 3.5))
    x = [r["env_steps"] for r in curve]
    ax.plot(x[1:], [r["train_return"] for r in curve[1:]], label="training (mean of +- directions)")
    val = [(r["env_steps"], r["validation_return"]) for r in curve if r["validation_return"] != ""]
    ax.plot([v[0] for v in val], [v[1] for v in val], "o-", label="held-out (validation seeds)")
    ax.set_xlabel("environment steps")
    ax.set_ylabel("episode return")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    with atomic_file(path) as fh:
        fig.savefig(fh, format="png", dpi=110)
    plt.close(fig)
    return path


def command_line(cfg: TrainConfig) -> str:
    """The ``auvtrack train`` command of ``cfg`` (without ``--out``), recorded in the provenance.

    Parameters
    ----------
    cfg : TrainConfig
        Settings.

    Returns
    -------
    str
        The command.
    """
    import shlex

    args = ["auvtrack", "train", "--suite", str(cfg.suite)]
    if cfg.method != "ars":
        args += ["--method", cfg.method]
    if cfg.action != "tau":
        args += ["--action", cfg.action]
    if cfg.tier is not None:
        args += ["--tier", cfg.tier]
    for t in cfg.tasks:
        args += ["--task", t]
    for name in ("iterations", "directions", "top", "step_size", "noise", "seeds_per_iteration", "eval_every",
                 "substeps", "seed"):
        args += ["--" + name.replace("_", "-"), repr(getattr(cfg, name))]
    if cfg.duration is not None:
        args += ["--duration", repr(cfg.duration)]
    if cfg.quick:
        args.append("--quick")
    return " ".join(shlex.quote(a) for a in args)


def train(cfg: TrainConfig, out: str | Path, *, progress: Callable[[dict], None] | None = None,
          client=None, notify: Callable[[str], None] | None = None, compile_bar: bool = False) -> TrainResult:
    """Train (or resume training) a linear policy; write the policy file, the curve and a checkpoint.

    Parameters
    ----------
    cfg : TrainConfig
        The settings.
    out : str or Path
        Output folder: ``checkpoint.npz`` (resumed when present and of the same settings; a larger
        ``iterations`` continues it), ``policy.npz``, ``curve.csv``, ``curve.png``.
    progress : callable, optional
        Called with each curve row as its iteration completes (it may raise to stop: the
        checkpoint holds every completed iteration).
    client : distributed.Client, optional
        Run each iteration's training rollouts on its workers (one task per training task; each
        worker keeps its environments); the numbers are those of a local training.  The held-out
        evaluations run here.  The caller closes the client.
    notify : callable, optional
        Receives the "compiling kernels (first run only, about N s)" notice when the environments'
        step is not cached yet (:func:`auvtrack.gym.env.compile_steps`; default standard error).
    compile_bar : bool, optional
        A progress bar over the functions compiled before the first episode.

    Returns
    -------
    TrainResult
        The policy, the curve and the budget spent.
    """
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    trainer = _Trainer(cfg, notify, compile_bar)
    trainer.client = client
    ckpt = out / CHECKPOINT
    if ckpt.is_file():
        j, M, stats, res, fitness = _load_checkpoint(ckpt, cfg)
    else:
        j, M, stats, fitness = 0, np.zeros((3, OBS.size)), _Stats(), []
        res = TrainResult(M, stats.mean, stats.std())
    if cfg.method == "cmaes":
        trainer.start_cmaes(fitness)
    session = time.perf_counter()
    wall0 = res.wall_s

    def finish() -> TrainResult:  # from the checkpoint: an iteration cut short leaves no trace
        _, M_done, stats_done, done, _ = _load_checkpoint(ckpt, cfg)
        res.M, res.mean, res.std, res.curve = M_done, stats_done.mean, stats_done.std(), done.curve
        res.episodes, res.env_steps, res.wall_s = done.episodes, done.env_steps, done.wall_s
        policy = save_policy(out / "policy.npz", [res.M], [np.zeros(3)], ["identity"], trainer.scale, res.mean, res.std,
                             provenance=_provenance(cfg, trainer.suite, trainer.tier, trainer.tasks, res),
                             commands=cfg.action)
        csv_path, png = _write_curve(out, res.curve)
        res.outputs = {"policy": policy, "curve_csv": csv_path, "checkpoint": ckpt,
                       **({"curve_png": png} if png else {})}
        return res

    if not res.curve:  # iteration 0: the initial policy, held out
        res.curve.append({"iteration": 0, "episodes": 0, "env_steps": 0, "train_return": "",
                          "validation_return": trainer.validation_return(M, stats.mean, stats.std()), "wall_s": 0.0})
        _save_checkpoint(ckpt, cfg, 0, M, stats, res, trainer.fitness)
    try:
        while j < cfg.iterations:
            M, r_train, episodes, steps = trainer.iteration(j, M, stats)
            j += 1
            res.episodes += episodes
            res.env_steps += steps
            res.wall_s = wall0 + time.perf_counter() - session
            evaluate = j % cfg.eval_every == 0 or j == cfg.iterations
            row = {"iteration": j, "episodes": res.episodes, "env_steps": res.env_steps, "train_return": r_train,
                   "validation_return": trainer.validation_return(M, stats.mean, stats.std()) if evaluate else "",
                   "wall_s": round(res.wall_s, 3)}
            res.curve.append(row)
            _save_checkpoint(ckpt, cfg, j, M, stats, res, trainer.fitness)
            if progress is not None:
                progress(row)
    finally:
        finish()
    return res

