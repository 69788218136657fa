"""6-DOF truth models: kinematics, mass matrices, energy, P01 Munk terms, PVS reference, actuators, allocation."""
from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from auvtrack.plant.sixdof import fossen, prestero
from auvtrack.plant.sixdof.actuators import effective
from auvtrack.vehicle.kinematics import attitude
from auvtrack.plant.sixdof.layout import (CMD_DR, CMD_DS, CMD_N, NX6, P_B, P_DMAX, P_MA, P_MINV, P_MODEL,
                                    P_MRB, P_NMAX, P_W, PP6_SIZE)
from auvtrack.vehicle.truth_presets import SHIPPED6, SHIPPED_FILES6, available6, load_preset6
from auvtrack.plant.sixdof.rigid import (euler_rates, kirchhoff, ned_velocity, body_from_ned6, rotation,
                                   skew, trig6)
from auvtrack.plant.sixdof.truth import MODELS, initial_state, integrate_open_loop, pack_truth

DATA = Path(__file__).resolve().parents[1] / "data"
angles = st.tuples(st.floats(-math.pi, math.pi), st.floats(-1.4, 1.4), st.floats(-math.pi, math.pi))
rates = st.tuples(*(st.floats(-1.0, 1.0),) * 3)


def _R(phi, theta, psi):
    return np.array(rotation(trig6(phi, theta, psi)))


# --- kinematics ---------------------------------------------------------------------------------

@settings(max_examples=60, deadline=None)
@given(angles)
def test_rotation_is_proper_orthogonal_and_zyx(ang):
    R = _R(*ang)
    assert np.allclose(R @ R.T, np.eye(3), atol=1e-14)
    assert np.linalg.det(R) == pytest.approx(1.0, abs=1e-14)
    phi, theta, psi = ang
    Rz = np.array([[math.cos(psi), -math.sin(psi), 0], [math.sin(psi), math.cos(psi), 0], [0, 0, 1]])
    Ry = np.array([[math.cos(theta), 0, math.sin(theta)], [0, 1, 0], [-math.sin(theta), 0, math.cos(theta)]])
    Rx = np.array([[1, 0, 0], [0, math.cos(phi), -math.sin(phi)], [0, math.sin(phi), math.cos(phi)]])
    assert np.allclose(R, Rz @ Ry @ Rx, atol=1e-14)  # Fossen 2021 eq. (2.18): R = Rz Ry Rx


@settings(max_examples=60, deadline=None)
@given(angles, rates)
def test_euler_rates_against_finite_differences_of_the_rotation(ang, w):
    """d/dt R(Theta) = R S(omega) along Theta_dot = T(Theta) omega (central differences, h = 1e-6)."""
    tr = trig6(*ang)
    td = np.array(euler_rates(tr, *w))
    h = 1e-6
    dR = (_R(*(np.array(ang) + h * td)) - _R(*(np.array(ang) - h * td))) / (2 * h)
    assert np.allclose(dR, _R(*ang) @ skew(w), atol=1e-7)


@settings(max_examples=40, deadline=None)
@given(angles, rates)
def test_ned_and_body_transforms_are_inverse(ang, v):
    tr = trig6(*ang)
    assert np.allclose(body_from_ned6(tr, *ned_velocity(tr, *v)), v, atol=1e-14)
    assert np.allclose(ned_velocity(tr, *v), _R(*ang) @ np.array(v), atol=1e-14)


@pytest.mark.parametrize("name", SHIPPED6)
def test_state_derivative_kinematic_part(name):
    pp = pack_truth(name)
    x = initial_state((1.0, 2.0, 3.0, 0.2, -0.3, 1.1), (1.2, 0.1, -0.05, 0.03, 0.02, -0.04))
    dx = np.zeros(NX6)
    MODELS[name].derivative(x, attitude(x[4], x[5]), (0.0, 0.0, 0.0), (0.0,) * 6, np.zeros(6), pp, dx)
    tr = trig6(*x[3:6])
    assert np.allclose(dx[0:3], ned_velocity(tr, *x[6:9]), rtol=0, atol=1e-15)
    assert np.allclose(dx[3:6], euler_rates(tr, *x[9:12]), rtol=0, atol=1e-15)


# --- mass matrices --------------------------------------------------------------------------------

@pytest.mark.parametrize("name", SHIPPED6)
def test_mass_matrices_symmetric_positive_definite(name):
    pp = pack_truth(name)
    M_rb = pp[P_MRB:P_MRB + 36].reshape(6, 6)
    M_a = pp[P_MA:P_MA + 36].reshape(6, 6)
    M = M_rb + M_a
    for A in (M_rb, M_a, M):
        assert np.array_equal(A, A.T)
    assert np.linalg.eigvalsh(M_rb).min() > 0 and np.linalg.eigvalsh(M).min() > 0
    assert np.allclose(pp[P_MINV:P_MINV + 36].reshape(6, 6) @ M, np.eye(6), atol=1e-12)


def test_prestero_mass_matrix_entries():
    """P01: m = W/g, CG offset z_g couples surge-pitch and sway-roll; Y_rdot, Z_qdot off-diagonal."""
    M_rb, M_a = prestero.mass_matrices(load_preset6("remus100_prestero"))
    m, zg = 299.0 / 9.81, 0.0196
    assert M_rb[0, 0] == pytest.approx(m) and M_rb[0, 4] == pytest.approx(m * zg)
    assert M_rb[1, 3] == pytest.approx(-m * zg) and M_rb[4, 4] == 3.45
    assert (M_a[0, 0], M_a[1, 1], M_a[4, 4], M_a[1, 5], M_a[2, 4]) == (0.93, 35.5, 4.88, -1.93, 1.93)


def test_fossen_rigid_body_matches_the_cg_transformation():
    """M_RB about the CO = H(r_g)^T M_CG H(r_g) (Fossen 2021 eq. 3.42) and Lamb's factors in (0, 1)."""
    dd = fossen.derived(load_preset6("remus100_fossen"))
    H = np.eye(6)
    H[0:3, 3:6] = skew([0.0, 0.0, 0.02]).T
    M_cg = np.diag([dd["m"]] * 3 + [dd["Ix"], dd["Iy"], dd["Iy"]])
    assert np.allclose(dd["M_rb"], H.T @ M_cg @ H, atol=1e-13)
    assert all(0 < k < 1 for k in dd["k"])
    assert dd["m"] == pytest.approx(4 / 3 * math.pi * 1026 * 0.8 * 0.095 ** 2)


# --- energy of the unforced, undamped rigid body with added mass ----------------------------------

def _conservative(name: str) -> np.ndarray:
    """pp with every force but rigid-body and added-mass inertia removed."""
    pp = pack_truth(name)
    pp[P_W] = pp[P_B] = 0.0
    if name == "remus100_prestero":
        pp[P_MODEL:prestero.R_N0] = 0.0          # drag, lift, fins, thrust and torque
    else:
        pp[fossen.FZ_S] = pp[fossen.FZ_CCF] = 0.0   # hull lift/drag, cross-flow
        pp[fossen.FZ_D0:fossen.FZ_D0 + 6] = 0.0       # linear damping
        pp[fossen.FZ_KR] = pp[fossen.FZ_KS] = 0.0     # fins
        pp[fossen.FZ_KT0:fossen.FZ_KQMAX + 1] = 0.0   # propeller
    return pp


def _energy_drift(name, dt, t_end=20.0):
    pp = _conservative(name)
    M = np.linalg.inv(pp[P_MINV:P_MINV + 36].reshape(6, 6))
    x = initial_state((0, 0, 0, 0.1, 0.2, 0.3), (0.8, 0.3, -0.2, 0.6, 0.5, -0.7))
    cmd = np.zeros(6)
    def f(z, vc, dist, cmd, pp, out):
        MODELS[name].derivative(z, attitude(z[4], z[5]), vc, dist, cmd, pp, out)
    k = [np.zeros(NX6) for _ in range(4)]
    E0 = 0.5 * x[6:12] @ M @ x[6:12]
    for _ in range(int(round(t_end / dt))):
        f(x, (0.0, 0.0, 0.0), (0.0,) * 6, cmd, pp, k[0])
        f(x + 0.5 * dt * k[0], (0.0, 0.0, 0.0), (0.0,) * 6, cmd, pp, k[1])
        f(x + 0.5 * dt * k[1], (0.0, 0.0, 0.0), (0.0,) * 6, cmd, pp, k[2])
        f(x + dt * k[2], (0.0, 0.0, 0.0), (0.0,) * 6, cmd, pp, k[3])
        x = x + dt / 6 * (k[0] + 2 * k[1] + 2 * k[2] + k[3])
    return abs(0.5 * x[6:12] @ M @ x[6:12] - E0) / E0


@pytest.mark.parametrize("name", SHIPPED6)
def test_kinetic_energy_conserved_to_rk4_order(name):
    """1/2 nu^T M nu is invariant (nu^T C(nu) nu = 0): the drift is integration error only and
    shrinks at least as fast as dt^4, RK4's order (measured: 4.9 Prestero, 4.5-4.8 Fossen)."""
    d1, d2 = _energy_drift(name, 0.04), _energy_drift(name, 0.02)
    order = math.log2(d1 / d2)
    assert 3.8 < order < 5.5, (d1, d2, order)
    assert d2 < 1e-7


# --- Prestero: the Munk terms derived from M_A reproduce P01's printed cross terms ----------------

_P01_TERMS = {"X_wq": (0, 2, 4), "X_qq": (0, 4, 4), "X_vr": (0, 1, 5), "X_rr": (0, 5, 5),
              "Y_ura": (1, 0, 5), "Y_wp": (1, 2, 3), "Y_pq": (1, 3, 4), "Z_uqa": (2, 0, 4),
              "Z_vp": (2, 1, 3), "Z_rp": (2, 3, 5), "M_uwa": (4, 0, 2), "M_vp": (4, 1, 3),
              "M_uqa": (4, 0, 4), "N_uva": (5, 0, 1), "N_wp": (5, 2, 3), "N_ura": (5, 0, 5)}


def test_prestero_munk_terms_match_p01_printed_values():
    pr = load_preset6("remus100_prestero")
    _, M_a = prestero.mass_matrices(pr)
    c = prestero.munk_coefficients(M_a)
    for name, (k, i, j) in _P01_TERMS.items():
        printed = pr.values[f"added_mass_cross_terms.{name}"]
        half_digit = 0.5 * 10 ** (math.floor(math.log10(abs(printed))) - 2)  # 3 significant digits
        assert abs(c[k, i, j] - printed) <= half_digit + 1e-12, (name, c[k, i, j], printed)
    # M_rp, N_pq = +-(K_pdot - N_rdot): P01 prints 4.86, i.e. K_pdot = -1.41e-2 (its final table has -7.04e-2)
    kp, nr = pr.values["added_mass.K_pdot"], pr.values["added_mass.N_rdot"]
    assert c[4, 3, 5] == pytest.approx(kp - nr, abs=1e-12) and c[5, 3, 4] == pytest.approx(-(kp - nr), abs=1e-12)
    assert abs((-0.0141 - nr) - pr.values["added_mass_cross_terms.M_rp"]) < 0.01
    # an axisymmetric vehicle with Y_vdot = Z_wdot and M_qdot = N_rdot has no Munk roll moment
    assert np.allclose(c[3], 0.0, atol=1e-12)


def test_prestero_total_coefficients_equal_p01_combined():
    """Munk part + lift part of every u-proportional term = P01's combined coefficient."""
    pr = load_preset6("remus100_prestero")
    _, M_a = prestero.mass_matrices(pr)
    c = prestero.munk_coefficients(M_a)
    lift = prestero.lift_coefficients(pr, M_a)
    for name, k, i, j in prestero._LIFT_TERMS:
        assert c[k, i, j] + lift[name] == pytest.approx(pr.values[f"combined.{name}"], abs=1e-12)
    assert lift["Y_ur"] == pytest.approx(6.15) and lift["M_uq"] == pytest.approx(-3.93)


def _derivative(name, x, cmd=(0.0, 0.0, 0.0), pp=None, dist=(0.0,) * 6):
    pp = pack_truth(name) if pp is None else pp
    c = np.zeros(6)
    c[0:3] = cmd
    dx = np.zeros(NX6)
    x = np.asarray(x, float)
    MODELS[name].derivative(x, attitude(x[4], x[5]), (0.0, 0.0, 0.0), tuple(dist), c, pp, dx)
    return dx


def test_prestero_analytic_equilibria():
    """With W = B and no propeller torque, u = sqrt(X_prop / -X_u|u|) at n = n0 is an equilibrium;
    at rest a roll moment K is balanced at sin(phi) = K / (z_g W); P01's 7 N of buoyancy lifts."""
    pp = pack_truth("remus100_prestero")
    pp[P_B] = pp[P_W]
    pp[prestero.R_KPROP] = 0.0
    x = initial_state(nu6=(math.sqrt(3.86 / 1.62), 0, 0, 0, 0, 0), actuators=(0.0, 0.0, 1500.0))
    dx = _derivative("remus100_prestero", x, (0.0, 0.0, 1500.0), pp)
    assert np.abs(dx[3:]).max() < 1e-13 and dx[0] == x[6]
    phi = math.asin(-0.543 / (0.0196 * 299.0))
    dx = _derivative("remus100_prestero", initial_state((0, 0, 0, phi, 0, 0)), pp=pp,
                     dist=(0.0, 0.0, 0.0, -0.543, 0.0, 0.0))
    assert np.abs(dx).max() < 1e-13
    M = np.linalg.inv(pack_truth("remus100_prestero")[P_MINV:P_MINV + 36].reshape(6, 6))
    dx = _derivative("remus100_prestero", initial_state())
    assert np.allclose(M @ dx[6:12], [0, 0, 299.0 - 306.0, 0, 0, 0], atol=1e-12)


def _jacobian_eigenvalues(name, rpm):
    """Eigenvalues of the linearisation about straight, level running at the steady speed of ``rpm``
    (W = B and no propeller torque for P01, so that straight running is an equilibrium)."""
    pp = pack_truth(name)
    if name == "remus100_prestero":
        pp[P_B] = pp[P_W]
        pp[prestero.R_KPROP] = 0.0
    x = initial_state(actuators=(0.0, 0.0, rpm))
    u = 1.0
    for _ in range(50):  # Newton on the surge balance
        x[6] = u
        f0 = _derivative(name, x, (0, 0, rpm), pp)[6]
        x[6] = u + 1e-6
        u -= f0 / ((_derivative(name, x, (0, 0, rpm), pp)[6] - f0) / 1e-6)
    x[6] = u
    idx = [3, 4, 7, 8, 9, 10, 11]  # phi, theta, v, w, p, q, r (position and yaw are neutral)
    J = np.zeros((7, 7))
    for k, j in enumerate(idx):
        a, b = x.copy(), x.copy()
        a[j] += 1e-7
        b[j] -= 1e-7
        J[:, k] = (_derivative(name, a, (0, 0, rpm), pp) - _derivative(name, b, (0, 0, rpm), pp))[idx] / 2e-7
    return u, np.linalg.eigvals(J)


def test_open_loop_stability_at_cruise():
    """A property of the sources, pinned: P01's coefficients make the REMUS open-loop unstable at
    cruise (Munk moments N_uv = -24, M_uw = +24 kg against small fin damping N_ur = M_uq = -2 kg m),
    while Fossen's model, which zeroes those Munk terms, is stable.  At 1500 rpm (1.54 m/s)."""
    u, ev = _jacobian_eigenvalues("remus100_prestero", 1500.0)
    assert u == pytest.approx(1.5436, abs=1e-4)
    assert ev.real.max() > 0.5
    u, ev = _jacobian_eigenvalues("remus100_fossen", 1500.0)
    assert ev.real.max() < 0


def test_shipped_presets_have_sources():
    assert set(SHIPPED6) | set(SHIPPED_FILES6) == set(available6())
    for name in SHIPPED6:
        pr = load_preset6(name)
        for sec in pr.record.values():
            for e in sec.values():
                assert e["unit"] and e["source"]


# --- the PVS reference case ------------------------------------------------------------------------

def test_fossen_reproduces_pvs_open_loop_reference():
    """PVS remus100.py (c717e07) from rest, delta_r = 0.1, delta_s = -0.05 rad, 1200 rpm: within 2 cm
    in position and 2e-3 (rad, m/s, rad/s) elsewhere at 5, 10, 20 and 30 s (our RK4, dt = 5 ms)."""
    ref = json.loads((DATA / "remus100_fossen_openloop.json").read_text())
    c = ref["commands"]
    times = (5.0, 10.0, 20.0, 30.0)
    res = integrate_open_loop("remus100_fossen", (c["delta_r"], c["delta_s"], c["rpm"]), 30.0, 0.005,
                              times=times)
    for t in times:
        s, x = ref["states"][str(t)], res[t]
        assert np.abs(x[0:3] - s["eta"][0:3]).max() < 0.02, t
        assert np.abs(x[3:6] - s["eta"][3:6]).max() < 2e-3, t
        assert np.abs(x[6:12] - np.array(s["nu"])).max() < 2e-3, t
        assert np.abs(x[12:14] - np.array(s["u_actual"][0:2])).max() < 2e-3, t
        assert abs(x[14] - s["u_actual"][2]) < 2e-3 * c["rpm"], t


# --- actuators --------------------------------------------------------------------------------------

@pytest.mark.parametrize("name", SHIPPED6)
def test_actuator_first_order_lag_and_limit(name):
    pp = pack_truth(name)
    T = 0.1
    res = integrate_open_loop(name, (0.1, 0.5, 1000.0), 0.3, 0.001, times=(0.1, 0.3))
    assert res[0.1][12] == pytest.approx(0.1 * (1 - math.exp(-1.0)), rel=1e-9)   # delta_r lag, T = 0.1 s
    # held at the 15 deg limit: the applied (clipped) angle is the limit; the state stops within
    # one step's travel (RK4 stages may cross the limit inside the step where it is reached)
    assert effective(res[0.3], pp)[1] == pp[P_DMAX]
    assert 0.0 <= res[0.3][13] - pp[P_DMAX] < 0.001 * (0.5 - pp[P_DMAX]) / T
    assert res[0.3][14] == pytest.approx(1000.0 * (1 - math.exp(-0.3)), rel=1e-9)  # rpm lag, T_n = 1 s
    assert T == pp[118]


def test_fin_rate_limit_acts():
    pp = pack_truth("remus100_fossen", {"delta_rate_max": 0.05})
    x = initial_state()
    dx = np.zeros(NX6)
    cmd = np.zeros(6)
    cmd[CMD_DR] = 0.2
    fossen.derivative(x, attitude(0.0, 0.0), (0.0, 0.0, 0.0), (0.0,) * 6, cmd, pp, dx)
    assert dx[12] == 0.05  # (0.2 - 0)/0.1 = 2 rad/s limited to 0.05


def test_actuator_settings_out_of_range_are_refused():
    with pytest.raises(ValueError, match=r"plant.n_max: must be rpm, > 0 \(got -5.0\)"):
        pack_truth("remus100_prestero", {"n_max": -5})
    with pytest.raises(ValueError, match="plant.delta_max"):
        pack_truth("remus100_fossen", {"delta_max": 2.0})


# --- allocation ---------------------------------------------------------------------------------------

def _alloc(name, tau, nu, pp):
    cmd = np.zeros(6)
    if name == "remus100_prestero":
        bits = prestero.allocate_tau(*tau, nu[0], pp, cmd)
        prod = prestero.produced(nu[0], cmd[CMD_DR], cmd[CMD_DS], cmd[CMD_N], pp)
    else:
        bits = fossen.allocate_tau(*tau, *nu, pp, cmd)
        prod = fossen.produced(*nu, cmd[CMD_DR], cmd[CMD_DS], cmd[CMD_N], pp)
    return bits, cmd, np.array(prod)


@settings(max_examples=200, deadline=None)
@given(st.sampled_from(SHIPPED6), st.floats(0.3, 2.5), st.floats(-0.2, 0.2), st.floats(-0.2, 0.2),
       st.floats(-0.9, 0.9), st.floats(-0.9, 0.9), st.floats(-0.9, 0.9))
def test_allocation_inverts_the_actuator_model(name, u, v, w, fu, fq, fr):
    """Inside the actuators' reach, tau produced by the allocated commands = tau commanded (1e-9)."""
    pp = pack_truth(name)
    nu = (u, v, w)
    # the reach at this speed: what full fin and full rpm produce
    full = _alloc(name, (1e6, 1e6, 1e6), nu, pp)[2]
    tau = (fu * 0.5 * full[0], fq * abs(full[1]), fr * abs(full[2]))
    bits, cmd, prod = _alloc(name, tau, nu, pp)
    assert bits == 0
    assert np.allclose(prod, tau, rtol=0, atol=1e-9)


@pytest.mark.parametrize("name", SHIPPED6)
def test_allocation_saturates_and_reports(name):
    pp = pack_truth(name)
    # beyond reach at 1 m/s: every channel saturates, at the limit, with the commanded sign
    bits, cmd, prod = _alloc(name, (500.0, 50.0, -50.0), (1.0, 0.0, 0.0), pp)
    assert bits == 7
    assert abs(cmd[CMD_DR]) == pp[P_DMAX] and abs(cmd[CMD_DS]) == pp[P_DMAX] and cmd[CMD_N] == pp[P_NMAX]
    assert prod[1] > 0 and prod[2] < 0
    # at rest the fins produce nothing: a moment saturates, zero does not
    bits, cmd, _ = _alloc(name, (0.0, 1.0, 0.0), (0.0, 0.0, 0.0), pp)
    assert bits == 2 and abs(cmd[CMD_DS]) == pp[P_DMAX] and cmd[CMD_DR] == 0.0
    # reverse thrust is produced by negative rpm
    bits, cmd, prod = _alloc(name, (-2.0, 0.0, 0.0), (0.0, 0.0, 0.0), pp)
    assert bits == 0 and cmd[CMD_N] < 0 and prod[0] == pytest.approx(-2.0, abs=1e-9)


@pytest.mark.parametrize("name", SHIPPED6)
def test_trim_rpm_balances_surge(name):
    from auvtrack.plant.sixdof.truth import trim_rpm
    pp = pack_truth(name)
    n = trim_rpm(name, pp, 1.0)
    x = initial_state(nu6=(1.0, 0, 0, 0, 0, 0), actuators=(0.0, 0.0, n))
    M = np.linalg.inv(pp[P_MINV:P_MINV + 36].reshape(6, 6))
    assert abs(M[0] @ _derivative(name, x, (0.0, 0.0, n), pp)[6:12]) < 1e-9  # surge force balance
    assert trim_rpm(name, pp, 0.0) == 0.0
    if name == "remus100_prestero":  # T = X_prop (n/n0)^2 = -X_u|u| u^2
        assert n == pytest.approx(1500.0 * math.sqrt(1.62 / 3.86), rel=1e-9)
    with pytest.raises(ValueError, match="initial.nu: surge speed u = 5 m/s needs more"):
        trim_rpm(name, pp, 5.0)
