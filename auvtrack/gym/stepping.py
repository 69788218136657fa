"""The compiled step of the environments: one control period (ZOH, ``ctrl_every`` RK4 steps) of N runs.

:func:`env_step` is the body of the engine's loop (:func:`auvtrack.engine.loop.run`, sampled-data
mode) cut at control samples: the same stage, metrics and stop checks in the same order, so that an
episode driven by the replay law (:mod:`auvtrack.gym.replay`) integrates the numbers of an engine
run of the same actions.  Like the engine's parts it is valid Python here (its names are the engine loop's); :func:`step_module`
writes, per plant, a module that imports the (replay, plant) kernel module and compiles a copy.
Inputs are the engine's :class:`~auvtrack.engine.loop.Stacked` (row i = env i); the per-env state
is a :class:`Carry`.
"""
from __future__ import annotations

import inspect
from typing import NamedTuple

import numpy as np

from ..control.contract import WORK_SIZE
from ..engine import kernels
from ..control.policy_observation import observe
from ..engine.loop import (  # the engine's parts this step is built of (rebound in the generated module)
    CAUSE_CONTROLLER, CAUSE_NONE, SF, SI, Buffers, LawOutputs, Loop, Settings, advance, attitude, first_stage,
    Rk4, measure, plant, prange, sample, state_free_disturbance, take_step,
)
from ..metrics import (
    METRICS_SIZE, OFF_ACT_LIMIT, OFF_ACT_TV, OFF_E2, OFF_EMAX, OFF_PATH, OFF_TEN, OFF_TV, PATH_AL2, PATH_VT2, PATH_XT2,
    PATH_XTMAX, metrics_init,
)
from ..plant.contract import SCRATCH_SIZE

__all__ = ["Carry", "new_carry", "step_module", "episode_cost", "COST_TERMS", "REWARD", "PENALTY", "PARALLEL_FROM"]

PARALLEL_FROM = 256
"""Envs from which a step runs in the thread pool (``step_all``) rather than in one thread (``step_serial``)."""

COST_TERMS = ("rmse", "energy", "tv", "xtrack_rmse", "vtrack_rmse", "along_rmse", "max_error", "xtrack_max",
              "act_rate_u", "act_rate_q", "act_rate_r", "t_act_limit_u", "t_act_limit_q", "t_act_limit_r")
"""The episode cost's terms (:func:`episode_cost`), named by the suite ``[run_score]`` criterion each charges,
in the order of their weights and caps in ``Carry.rw``."""
N_COST = len(COST_TERMS)
REWARD = tuple(f"k_{n}" for n in COST_TERMS) + tuple(f"cap_{n}" for n in COST_TERMS) + ("penalty",)
"""Reward terms per env (row of ``Carry.rw``): see :func:`episode_cost`."""
PENALTY = len(REWARD) - 1
"""Index of the failure penalty in ``Carry.rw``."""


class Carry(NamedTuple):
    """What N environments keep between steps (row i = env i)."""

    xp: np.ndarray
    xc: np.ndarray
    cmd: np.ndarray
    tau1: np.ndarray
    kc1: np.ndarray
    acc: np.ndarray
    refm: np.ndarray
    scr: np.ndarray
    work: np.ndarray
    ks: np.ndarray
    obs: np.ndarray
    reward: np.ndarray
    cause: np.ndarray
    rw: np.ndarray


def new_carry(n: int, nxp: int, nxc: int, ncmd: int, nobs: int) -> Carry:
    """Fresh per-env state arrays for ``n`` environments.

    Parameters
    ----------
    n : int
        Environments.
    nxp, nxc, ncmd, nobs : int
        Plant states, controller states, plant commands, observation size.

    Returns
    -------
    Carry
        Zeroed arrays (metrics accumulators initialised).
    """
    acc = np.zeros((n, METRICS_SIZE))
    for i in range(n):
        metrics_init(acc[i])
    return Carry(np.zeros((n, nxp)), np.zeros((n, nxc)), np.zeros((n, ncmd)), np.zeros((n, 3)), np.zeros((n, nxc)),
                 acc, np.zeros((n, 3, 3)), np.zeros((n, SCRATCH_SIZE)), np.zeros((n, WORK_SIZE)),
                 np.zeros((n, 2), np.int64), np.zeros((n, nobs)), np.zeros(n), np.zeros(n, np.int64),
                 np.zeros((n, len(REWARD))))


def env_step(ins, c, i, bound):
    """One control period of env ``i``: write ``c.obs[i]``, ``c.reward[i]``, ``c.cause[i]``; return the cause.

    The engine loop's step (:func:`~auvtrack.engine.loop.run`, sampled-data mode): the same
    kernel parts (:func:`~auvtrack.engine.loop.sample`, ``first_stage``, ``advance``, ``take_step``)
    in the same order, from step ``ks[i, 0]`` to the next control sample.  The reward is minus the
    increment of :func:`episode_cost` over the period; a failure adds ``-rw[PENALTY]``.
    ``ks[i]`` = (RK4 step, saturation flags).  At the end of the run (step ``n_steps``) nothing is
    integrated and the cause is 0.
    """
    si, sf = ins.si[i], ins.sf[i]
    xp, xc, acc = c.xp[i], c.xc[i], c.acc[i]
    rw = c.rw[i]
    n_steps, ctrl_every = si[SI.n_steps], si[SI.ctrl_every]
    dt = sf[SF.dt]
    nxp, nxc = xp.shape[0], xc.shape[0]
    rk = Rk4(np.zeros(nxp), np.zeros(nxp), np.zeros(nxp), np.zeros(nxp), c.kc1[i], np.zeros(nxc), np.zeros(nxc),
             np.zeros(nxc), np.empty(nxp), np.empty(nxc), np.empty(nxp), np.empty(nxc))  # kc1: the held law output
    cmd_sample = np.zeros(c.cmd.shape[1])
    buf = Buffers(c.refm[i], c.work[i], c.scr[i], c.cmd[i])
    lp = Loop(ins.pp[i], ins.cp[i], ins.vp[i], ins.path[i], ins.rows[i], ins.current[i], ctrl_every, ctrl_every * dt)
    out1, tau_s, aux_s = LawOutputs(c.tau1[i], rk.kc1, np.zeros(1)), np.zeros(3), np.zeros(1)
    outs = (LawOutputs(tau_s, rk.kc2, aux_s), LawOutputs(tau_s, rk.kc3, aux_s), LawOutputs(tau_s, rk.kc4, aux_s))
    reuse = state_free_disturbance(ins.rows[i])
    t_late = 0.5 * (sf[SF.win_t0] + min(sf[SF.win_t1], n_steps * dt))
    before = episode_cost(rw, acc)
    k, sat = c.ks[i, 0], c.ks[i, 1]
    cause = CAUSE_NONE
    for _ in range(ctrl_every):
        if k >= n_steps:
            break
        t = k * dt
        if k % ctrl_every == 0:
            status, sat_k = sample(t, k, xp, xc, lp, buf, ins.noise[i], out1, rk, cmd_sample)
            if status != 0:
                cause = CAUSE_CONTROLLER
                break
            sat = sat_k
        status, _, applied, eta, e = first_stage(t, xp, xc, lp, buf, rk, out1)
        if status == 0:
            status, cause = advance(t, dt, xp, xc, lp, buf, rk, e, applied, eta, sat, acc, Settings(si, sf), t_late,
                                    reuse, outs)
        if status != 0:
            cause = CAUSE_CONTROLLER
        if cause != CAUSE_NONE:
            break
        take_step(xp, xc, rk)
        k += 1
    c.ks[i, 0], c.ks[i, 1] = k, sat
    c.reward[i] = before - episode_cost(rw, acc) - (rw[PENALTY] if cause != CAUSE_NONE else 0.0)
    c.cause[i] = cause
    env_observe(ins, c, i, bound)
    return cause


def episode_cost(rw, acc):
    """The cost of the episode so far: sum over the terms of min(k * S, cap).

    S are the metrics accumulator's sums (:mod:`auvtrack.metrics`), in the order of
    :data:`COST_TERMS`: of squared virtual-point error times dt (m^2 s), of squared tau times dt,
    tau's total variation, the path-following sums at the navigation point over the window (squared
    cross-track, vertical-track and along-track error times dt, m^2 s; zero with ``metrics.path = false``),
    the largest |e_a| and the largest cross-track distance so far, each actuator's total variation
    (fractions of its limit) and its time at the limit (s).  ``rw`` = (k_1 .. k_n, cap_1 .. cap_n, penalty)
    (:data:`REWARD`).  Capped, so that a completed episode costs at most the sum of the caps (the failure
    penalty is more).
    """
    s_e, s_n, s_v, m_e = 0.0, 0.0, 0.0, 0.0
    for j in range(3):
        s_e += acc[OFF_E2 + j]
        s_n += acc[OFF_TEN + j]
        s_v += acc[OFF_TV + j]
        m_e = max(m_e, acc[OFF_EMAX + j])
    sums = (s_e, s_n, s_v, acc[OFF_PATH + PATH_XT2], acc[OFF_PATH + PATH_VT2], acc[OFF_PATH + PATH_AL2], m_e,
            acc[OFF_PATH + PATH_XTMAX], acc[OFF_ACT_TV], acc[OFF_ACT_TV + 1], acc[OFF_ACT_TV + 2], acc[OFF_ACT_LIMIT],
            acc[OFF_ACT_LIMIT + 1], acc[OFF_ACT_LIMIT + 2])
    n = N_COST
    cost = 0.0
    for j in range(n):
        cost += min(rw[j] * sums[j], rw[n + j])
    return cost


def env_observe(ins, c, i, bound):
    """The observation of env ``i`` at its current step (the measurement the law sees at that sample)."""
    xp, cp, path, noise = c.xp[i], ins.cp[i], ins.path[i], ins.noise[i]
    ctrl_every = ins.si[i][SI.ctrl_every]
    k = c.ks[i, 0]
    eta_t, nu_t = plant.pose(xp)
    row = k // ctrl_every
    if noise.shape[0] > 0 and row >= noise.shape[0]:
        row = noise.shape[0] - 1
    eta, nu = measure(eta_t, nu_t, noise, row)
    _, _, ap = plant.feedback(xp, c.cmd[i], ins.pp[i])
    observe(k * ins.sf[i][SF.dt], eta, nu, attitude(eta[3], eta[4]), path, ap, cp, bound, c.obs[i])


def step_all(ins, c, bound):
    """:func:`env_step` of every env (row) that has not ended, in a ``prange`` loop."""
    for i in prange(c.xp.shape[0]):
        if c.cause[i] == 0:
            env_step(ins, c, i, bound)


def step_serial(ins, c, bound):
    """:func:`step_all` in one thread (few envs: waking the thread pool costs more than the steps)."""
    for i in range(c.xp.shape[0]):
        if c.cause[i] == 0:
            env_step(ins, c, i, bound)


def observe_all(ins, c, bound):
    """:func:`env_observe` of every env."""
    for i in range(c.xp.shape[0]):
        env_observe(ins, c, i, bound)


PARTS = {"episode_cost": "njit(nogil=True, inline='always')", "env_step": "njit(nogil=True)", "env_observe": "njit(nogil=True)",
         "step_all": "njit(nogil=True, parallel=True)", "step_serial": "njit(nogil=True)", "observe_all": "njit(nogil=True)"}


def step_source(key: kernels.KernelKey) -> str:
    """Source of the step module of a (replay law, plant) pair: the kernel module's names and a copy of :data:`PARTS`."""
    parts = []
    for name, deco in PARTS.items():
        parts.append(f"@{deco}\n" + inspect.getsource(globals()[name]))
    head = f'''"""Environment step of one (replay law, plant) pair: generated by auvtrack.gym.stepping; do not edit."""
from numba import prange  # noqa: F401
from auvtrack.engine.kernels import KernelKey, kernel_module
from auvtrack.jit import njit  # noqa: F401
from auvtrack.control.policy_observation import observe  # noqa: F401
from auvtrack.metrics import OFF_ACT_LIMIT, OFF_ACT_TV, OFF_E2, OFF_EMAX, OFF_PATH, OFF_TEN, OFF_TV  # noqa: F401
from auvtrack.metrics import PATH_AL2, PATH_VT2, PATH_XT2, PATH_XTMAX  # noqa: F401
from auvtrack.gym.stepping import N_COST, PENALTY  # noqa: F401
_k = kernel_module(KernelKey({key.law!r}, {key.plant!r}, {key.label!r}))
globals().update({{n: getattr(_k, n) for n in dir(_k) if not n.startswith("__")}})
'''
    return head + "\n\n" + "\n\n".join(parts)


def step_module(key: kernels.KernelKey):
    """The generated step module of ``key`` (``step_all``, ``observe_all``), imported on first use.

    Parameters
    ----------
    key : KernelKey
        The (replay law, plant) pair.

    Returns
    -------
    module
        The module.
    """
    kernels.kernel_module(key)
    return kernels.generated_module(f"gym_{key.name}", lambda: step_source(key))
