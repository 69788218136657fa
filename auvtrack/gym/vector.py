"""``TrackVectorEnv``: N episodes of one suite cell stepped by one compiled call (a ``prange`` over the envs from :data:`~auvtrack.gym.stepping.PARALLEL_FROM` envs, one thread below).

Rows of the engine's :class:`~auvtrack.engine.loop.Stacked` inputs and of the
:class:`~auvtrack.gym.stepping.Carry` are the envs; :meth:`step` writes the actions into the rows'
replay tables and calls the step module's ``step_all`` once.  Autoreset follows Gymnasium's
default (``NEXT_STEP``): the step after an env ended resets it (seed index drawn from the vector
env's generator) and returns its first observation with reward 0; with ``autoreset="disabled"``
an ended env stays ended (not stepped, reward 0) until :meth:`reset`.  A reset prepares each new
seed index's run in Python (the prepared rows are kept for the next episode of that
index) and copies the rows of all the envs it resets in one assignment per array; the step itself
runs no per-env Python.  At an episode's end ``info`` carries its benchmark
metrics (``info["metrics"]``, ``info["status"]``, ``info["t"]``, object arrays, with the masks
``info["_metrics"]`` ... of the envs that ended, Gymnasium's vector-info convention).
"""
from __future__ import annotations

from pathlib import Path

import gymnasium as gym
import numpy as np
from gymnasium.vector import AutoresetMode, VectorEnv

from ..benchmark.suite import Suite
from ..control.policy_observation import OBS_BOUND
from ..engine.loop import CAUSES, SI
from ..metrics import metrics_finalize
from ..plant.contract import SF
from .env import TrackEnv
from .replay import GAINS
from .stepping import PARALLEL_FROM, new_carry


class TrackVectorEnv(VectorEnv):
    """``num_envs`` episodes of one cell (parameters as :class:`~auvtrack.gym.env.TrackEnv`).

    Parameters
    ----------
    num_envs : int
        Environments.
    suite, task, tier, action, substeps, duration
        As :class:`~auvtrack.gym.env.TrackEnv`.
    autoreset : str, optional
        ``"next_step"`` (default, Gymnasium's) or ``"disabled"``.
    """

    metadata = {"autoreset_mode": AutoresetMode.NEXT_STEP}
    AUTORESET = {"next_step": AutoresetMode.NEXT_STEP, "disabled": AutoresetMode.DISABLED}
    KEEP = 512
    """Prepared seed indices kept (the oldest is dropped beyond)."""

    def __init__(self, num_envs: int, suite: str | Path | Suite = "auv-track-v1", task: str | None = None,
                 tier: str | None = None, action: str = "tau", substeps: int = 10,
                 duration: float | None = None, autoreset: str = "next_step") -> None:
        if autoreset not in self.AUTORESET:
            raise ValueError(f"autoreset: must be one of {', '.join(self.AUTORESET)} (got {autoreset!r})")
        if not (isinstance(num_envs, (int, np.integer)) and num_envs >= 1):
            raise ValueError(f"num_envs: must be an integer >= 1 (got {num_envs!r})")
        self.metadata = {**self.metadata, "autoreset_mode": self.AUTORESET[autoreset]}
        self.num_envs = int(num_envs)
        self.one = TrackEnv(suite, task, tier, action=action, substeps=substeps, duration=duration)
        self.single_observation_space = self.one.observation_space
        self.single_action_space = self.one.action_space
        self.observation_space = gym.vector.utils.batch_space(self.single_observation_space, self.num_envs)
        self.action_space = gym.vector.utils.batch_space(self.single_action_space, self.num_envs)
        self.ins = self.carry = None
        self._done = np.zeros(self.num_envs, bool)
        self.seed_indices = np.zeros(self.num_envs, np.int64)
        self.windows = np.zeros((self.num_envs, 2))
        self._prepared: dict[int, tuple] = {}

    def _rows(self, index: int) -> tuple:
        """The prepared inputs, fresh carry and metrics window of seed index ``index`` (kept once made)."""
        if index not in self._prepared:
            if len(self._prepared) >= self.KEEP:
                self._prepared.pop(next(iter(self._prepared)))
            self.one.reset(seed=index)
            one_ins, one_c = self.one.ins, self.one.carry
            self._prepared[index] = (one_ins, type(one_c)(*[a.copy() for a in one_c]),
                                     tuple(self.one.prep.scenario.metrics.window))
        return self._prepared[index]

    def _load(self, envs: np.ndarray, indices: list[int]) -> None:
        """Prepare envs ``envs`` for seed indices ``indices`` and copy their rows in, one array at a time.

        Each new seed index is prepared once in Python (:meth:`_rows`); the copy is one
        assignment per input and carry array for all the envs at once, not one per env.
        """
        envs = np.asarray(envs, dtype=np.int64)
        if envs.size == 0:
            return
        made = [self._rows(int(index)) for index in indices]
        if self.ins is None:
            one_ins, one_c, _ = made[0]
            self.ins = type(one_ins)(*[np.repeat(a, self.num_envs, axis=0) for a in one_ins])
            self.carry = new_carry(self.num_envs, one_c.xp.shape[1], one_c.xc.shape[1], one_c.cmd.shape[1],
                                   one_c.obs.shape[1])
            self.kernels = self.one.kernels
        for j, dst in enumerate(self.ins):
            dst[envs] = np.concatenate([m[0][j] for m in made]) if len(made) > 1 else made[0][0][j]
        for j, dst in enumerate(self.carry):
            dst[envs] = np.concatenate([m[1][j] for m in made]) if len(made) > 1 else made[0][1][j]
        self.seed_indices[envs] = indices
        self.windows[envs] = [m[2] for m in made]

    def reset(self, *, seed: int | list[int] | None = None, options: dict | None = None):
        """Reset every env: seed indices ``seed + i`` (or the given list, or drawn).

        Parameters
        ----------
        seed : int or list of int, optional
            Seed index of env 0 (env i gets ``seed + i``), or one per env.
        options : dict, optional
            Unused.

        Returns
        -------
        (numpy.ndarray, dict)
            Observations (num_envs, OBS.size) and ``{"seed_index": array}``.
        """
        if isinstance(seed, (list, tuple)):
            seeds = [int(s) for s in seed]
        elif seed is not None:
            seeds = [int(seed) + i for i in range(self.num_envs)]
        else:
            seeds = None
        self._np_random, _ = gym.utils.seeding.np_random(None if seed is None else seeds[0])
        if seeds is None:
            seeds = [int(s) for s in self._np_random.integers(0, 2**31 - 1, self.num_envs)]
        self._load(np.arange(self.num_envs), seeds)
        self._done[:] = False
        return self.carry.obs.copy(), {"seed_index": self.seed_indices.copy()}

    def step(self, actions):
        """Step every env one control period in one compiled call (autoreset of the envs that ended).

        Parameters
        ----------
        actions : array_like
            (num_envs, 3) normalised commands.

        Returns
        -------
        tuple
            Observations, rewards, terminated, truncated, info (``metrics`` of the envs that ended
            is left to :class:`~auvtrack.gym.env.TrackEnv`; here ``seed_index``).
        """
        if self.carry is None:
            raise RuntimeError("call reset() before step()")
        a = np.clip(np.asarray(actions, dtype=np.float64).reshape(self.num_envs, 3), -1.0, 1.0)
        c, ins = self.carry, self.ins
        ended = np.flatnonzero(self._done)
        if self.metadata["autoreset_mode"] == AutoresetMode.NEXT_STEP:
            # these envs start a new episode now (one seed index drawn per env, in env order)
            self._load(ended, [int(self._np_random.integers(0, 2**31 - 1)) for _ in ended])
        ctrl_every = ins.si[:, SI.ctrl_every]
        rows = np.minimum(c.ks[:, 0] // ctrl_every, ins.cp[:, GAINS.n].astype(np.int64) - 1)
        cols = GAINS.table + 3 * rows[:, None] + np.arange(3)[None, :]
        ins.cp[np.arange(self.num_envs)[:, None], cols] = a
        live = ~self._done
        c.cause[~live] = -1  # the reset envs are not stepped this call
        step = self.kernels.step_all if self.num_envs >= PARALLEL_FROM else self.kernels.step_serial
        step(ins, c, OBS_BOUND)
        c.cause[~live] = 0
        reward = np.where(live, c.reward, 0.0)
        terminated = live & (c.cause != 0)
        truncated = live & ~terminated & (c.ks[:, 0] >= ins.si[:, SI.n_steps])
        ending = terminated | truncated
        disabled = self.metadata["autoreset_mode"] == AutoresetMode.DISABLED
        self._done = (self._done | ending) if disabled else ending
        info = {"seed_index": self.seed_indices.copy()}
        if ending.any():
            info.update(self.episode_infos(ending))
        return c.obs.copy(), reward, terminated, truncated, info

    def episode_infos(self, mask: np.ndarray) -> dict[str, np.ndarray]:
        """The benchmark metrics, status and end time of the envs in ``mask`` (vector-info form).

        Parameters
        ----------
        mask : numpy.ndarray
            (num_envs,) bool: the envs to report.

        Returns
        -------
        dict
            ``metrics``, ``status``, ``t`` (object arrays, None where not reported) and their masks
            ``_metrics``, ``_status``, ``_t``.
        """
        c, ins = self.carry, self.ins
        metrics, status, t = (np.full(self.num_envs, None, dtype=object) for _ in range(3))
        for i in np.flatnonzero(mask):
            t_end = int(c.ks[i, 0]) * float(ins.sf[i, SF.dt])
            t0, t1 = self.windows[i]
            metrics[i] = metrics_finalize(c.acc[i].copy(), t0, min(t1, t_end))
            cause = int(c.cause[i])
            status[i] = "ok" if cause == 0 else CAUSES.get(cause, ("controller", ""))[0]
            t[i] = t_end
        m = np.asarray(mask, bool).copy()
        return {"metrics": metrics, "status": status, "t": t, "_metrics": m, "_status": m.copy(), "_t": m.copy()}
