"""Evaluate the compiled FXTNTSMC law at seeded states; run as a script by tests/engine/test_vecmath.py.

``python tests/law_points.py OUT.npz [IN.npz]`` writes the inputs and the law's outputs
(status, tau, d/dt of the controller states, aux) at 3000 seeded states spread over the
envelope (|e_i| / rho_i log-uniform from 0.001 to 0.98, t in [0, 20] s) of Section 4, or at
the states of IN.npz.  The test runs it under both vector-math back ends, the second on the
states of the first, and compares.
"""
from __future__ import annotations

import sys

import numpy as np

from auvtrack.jit import njit
from auvtrack.control import fxtntsmc
from auvtrack.control.contract import WORK_SIZE, LawArgs, LawOutputs, Measured
from auvtrack.control.fxtntsmc.envelopes import baseline
from auvtrack.vehicle.kinematics import attitude, virtual_point
from auvtrack.vehicle.params import VP
from auvtrack.reference import eval_reference
from auvtrack.scenario import load_scenario
from auvtrack.simulation.pipeline import prepare

N_POINTS = 3000
NXP = 10  # Xs rows: the 5-DOF plant state, then the controller's state xc
XC = NXP + fxtntsmc.STATE.rho_bar
INF3 = (np.inf, np.inf, np.inf)
NEG_INF3 = (-np.inf, -np.inf, -np.inf)


@njit
def _evaluate(ts, Xs, atts, cp, vp, ref_p, status, taus, dXs, auxs):
    refm = np.zeros((3, 3))
    work = np.zeros(WORK_SIZE)
    for n in range(ts.shape[0]):
        X = Xs[n]
        eval_reference(ref_p, ts[n], refm)
        eta = (X[0], X[1], X[2], X[3], X[4])
        nu = (X[5], X[6], X[7], X[8], X[9])
        att = (atts[n, 0], atts[n, 1], atts[n, 2], atts[n, 3])
        args = LawArgs(refm, ref_p, cp, vp, NEG_INF3, INF3, (0.0, 0.0, 0.0), 0.0, work)
        status[n] = fxtntsmc.control(ts[n], Measured(eta, nu, att), X[NXP:], args, LawOutputs(taus[n], dXs[n], auxs[n]))


@njit
def _errors(ts, Xs, ref_p, ell, out):
    refm = np.zeros((3, 3))
    for n in range(ts.shape[0]):
        X = Xs[n]
        eval_reference(ref_p, ts[n], refm)
        eta = (X[0], X[1], X[2], X[3], X[4])
        p1 = virtual_point(eta, attitude(X[3], X[4]), ell)
        for i in range(3):
            out[n, i] = p1[i] - refm[0, i]


def _states(sc, prep) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(7)
    nx = NXP + prep.controller.x0.size
    ts = rng.uniform(0.0, 20.0, N_POINTS)
    Xs = np.zeros((N_POINTS, nx))
    refm = np.zeros((3, 3))
    for n, t in enumerate(ts):
        eval_reference(prep.ref_p, t, refm)
        Xs[n, 0:3] = refm[0] + rng.normal(0.0, [1.0, 0.3, 0.1])
        Xs[n, 3:5] = rng.normal(0.0, 0.2, 2) + [0.0, 0.1 * t + np.pi / 2]
        Xs[n, 5:10] = rng.normal(0.0, [0.5, 0.2, 0.2, 0.1, 0.1])
        Xs[n, XC + 3:] = prep.controller.x0[3:] + rng.normal(0.0, 0.3, nx - XC - 3)
    e = np.zeros((N_POINTS, 3))
    _errors(ts, Xs, prep.ref_p, prep.vp_nom[VP.ell], e)
    env = sc.envelope
    for n, t in enumerate(ts):  # rho_bar so that |e_i| / rho_i is a chosen ratio (or less)
        for i in range(3):
            rho1 = baseline(t, env.rho0[i], env.rho_inf[i], env.T, False)[0]
            Xs[n, XC + i] = max(0.0, abs(e[n, i]) / 10.0 ** rng.uniform(-3.0, np.log10(0.98)) - rho1)
    return ts, Xs


def main(out: str, given: str | None) -> None:
    sc = load_scenario("scenarios/paper.toml")
    prep = prepare(sc)
    if given is None:
        ts, Xs = _states(sc, prep)
    else:
        with np.load(given) as inp:
            ts, Xs = inp["ts"], inp["Xs"]
    nxc = prep.controller.x0.size
    status = np.zeros(N_POINTS, dtype=np.int64)
    taus, dXs, auxs = np.zeros((N_POINTS, 3)), np.zeros((N_POINTS, nxc)), np.zeros((N_POINTS, len(fxtntsmc.AUX_NAMES)))
    # the attitude by NumPy, the same numbers in both processes (the law's own functions differ)
    atts = np.stack([np.cos(Xs[:, 3]), np.sin(Xs[:, 3]), np.cos(Xs[:, 4]), np.sin(Xs[:, 4])], axis=1)
    _evaluate(ts, Xs, atts, prep.cp, prep.vp_nom, prep.ref_p, status, taus, dXs, auxs)
    np.savez(out, ts=ts, Xs=Xs, status=status, taus=taus, dXs=dXs, auxs=auxs)


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2] if len(sys.argv) > 2 else None)
