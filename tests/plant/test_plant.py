"""Plant mathematics: kinematics (eq. 1-3, ERRATA 1-2), derivatives, kinetics (eq. 1, 4)."""
import math

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from auvtrack.vehicle.dynamics import generalized_forces, nu_dot
from auvtrack.vehicle.kinematics import attitude, body_from_ned, eta_dot, j3, j3_dot, j3_inv, j4, j4_dot, virtual_point
from auvtrack.vehicle.presets import get_preset, pack_vehicle

angles = st.floats(-1.3, 1.3)
vel = st.floats(-2.0, 2.0)
ells = st.floats(0.1, 3.0)


def _state(th, ps, u, v, w, q, r):
    return np.array([0.3, -0.2, 1.1, th, ps]), np.array([u, v, w, q, r])


def _j1(th, ps):
    ct, stt, cp, sp = math.cos(th), math.sin(th), math.cos(ps), math.sin(ps)
    return np.array([[ct * cp, -sp, stt * cp], [ct * sp, cp, stt * sp], [-stt, 0, ct]])


def _rotation_zyx(ps, th):
    rz = np.array([[math.cos(ps), -math.sin(ps), 0], [math.sin(ps), math.cos(ps), 0], [0, 0, 1]])
    ry = np.array([[math.cos(th), 0, math.sin(th)], [0, 1, 0], [-math.sin(th), 0, math.cos(th)]])
    return rz @ ry


@given(angles, angles)
def test_j1_is_the_rotation_without_roll(th, ps):
    """ERRATA 1: J1 equals Rz(psi) Ry(theta) (the printed J1 is wrong)."""
    nu = np.array([0.7, -0.3, 0.2, 0.0, 0.0])
    out = np.array(eta_dot(attitude(th, ps), tuple(nu)))
    np.testing.assert_allclose(out[:3], _rotation_zyx(ps, th) @ nu[:3], atol=1e-14)
    np.testing.assert_allclose(out[:3], _j1(th, ps) @ nu[:3], atol=1e-14)
    # body_from_ned is its transpose: J1^T J1 v = v
    back = np.array(body_from_ned(attitude(th, ps), tuple(out[:3])))
    np.testing.assert_allclose(back, nu[:3], rtol=0, atol=1e-14)
    np.testing.assert_allclose(body_from_ned(attitude(th, ps), (1.0, -2.0, 0.5)),
                               _rotation_zyx(ps, th).T @ np.array([1.0, -2.0, 0.5]), rtol=0, atol=1e-14)


@settings(max_examples=60)
@given(angles, angles, vel, vel, vel, vel, vel, ells)
def test_virtual_point_velocity_by_finite_differences(th, ps, u, v, w, q, r, ell):
    """d/dt eta1 = J3 v1 + J4 (eq. 3, corrected J3[2,1] = -ell cos theta, ERRATA 2)."""
    eta, nu = _state(th, ps, u, v, w, q, r)
    h = 1e-6
    d = np.array(eta_dot(attitude(th, ps), tuple(nu)))

    def p1(x):
        return np.array(virtual_point(tuple(x), attitude(x[3], x[4]), ell))

    fd = (p1(eta + h * d) - p1(eta - h * d)) / (2 * h)
    J3 = np.array(j3(attitude(th, ps), ell))
    J4 = np.array(j4(attitude(th, ps), v, w))
    np.testing.assert_allclose(J3 @ np.array([u, q, r]) + J4, fd, atol=1e-8)


@given(angles, angles, ells)
def test_det_j3_is_ell_squared_and_inverse_is_exact(th, ps, ell):
    J3, Ji = np.array(j3(attitude(th, ps), ell)), np.array(j3_inv(attitude(th, ps), ell))
    assert math.isclose(abs(np.linalg.det(J3)), ell**2, rel_tol=1e-12)
    np.testing.assert_allclose(Ji @ J3, np.eye(3), atol=1e-12)


@settings(max_examples=60)
@given(angles, angles, vel, vel, vel, vel, vel, ells, vel, vel)
def test_j3_dot_and_j4_dot_by_finite_differences(th, ps, u, v, w, q, r, ell, vd, wd):
    """J3_dot, J4_dot along a trajectory with theta_dot = q, psi_dot = r / cos(theta)."""
    thd, psd = q, r / math.cos(th)
    h = 1e-6
    A = np.array(j3(attitude(th + h * thd, ps + h * psd), ell))
    B = np.array(j3(attitude(th - h * thd, ps - h * psd), ell))
    Jd = np.array(j3_dot(attitude(th, ps), thd, psd, ell))
    np.testing.assert_allclose(Jd, (A - B) / (2 * h), atol=1e-8)
    a = np.array(j4(attitude(th + h * thd, ps + h * psd), v + h * vd, w + h * wd))
    b = np.array(j4(attitude(th - h * thd, ps - h * psd), v - h * vd, w - h * wd))
    J4d = np.array(j4_dot(attitude(th, ps), v, w, thd, psd, vd, wd))
    np.testing.assert_allclose(J4d, (a - b) / (2 * h), atol=1e-8)


def test_kinetics_match_the_matrix_form():
    """nu_dot equals M^-1 (tau + omega - C(nu) nu - D nu - G) with the printed C0 (eq. 1)."""
    pre = get_preset("paper")
    vp = pack_vehicle(pre.m, pre.d, pre.wgml, pre.l, c_scale=1.1)
    m11, m22, m33, m44, m55 = pre.m
    rng = np.random.default_rng(3)
    for _ in range(20):
        eta = np.r_[rng.normal(size=3), rng.uniform(-1.2, 1.2, 2)]
        nu = rng.normal(size=5)
        u, v, w, q, r = nu
        C0 = np.array([[0, 0, 0, m33 * w, -m22 * v], [0, 0, 0, 0, m11 * u], [0, 0, 0, -m11 * u, 0],
                       [-m33 * w, 0, m11 * u, 0, 0], [m22 * v, -m11 * u, 0, 0, 0]])
        assert np.allclose(C0, -C0.T)  # skew-symmetric: Coriolis does no work
        tau3, omega = rng.normal(size=3), rng.normal(size=5)
        G = np.array([0, 0, 0, pre.wgml * math.sin(eta[3]), 0])
        rhs = np.array([tau3[0], 0, 0, tau3[1], tau3[2]]) + omega - 1.1 * C0 @ nu - np.diag(pre.d) @ nu - G
        att = attitude(eta[3], eta[4])
        out = np.array(nu_dot(att, tuple(nu), tuple(tau3), tuple(omega), vp))
        np.testing.assert_allclose(out, rhs / np.array(pre.m), rtol=1e-12, atol=1e-14)
        gf = np.array(generalized_forces(att, tuple(nu), vp))
        # reduced model (eq. 4): rows u, q, r of C nu are C_bar v1 with the printed C_bar
        Cbar = np.array([[0, m33 * w, -m22 * v], [(m11 - m33) * w, 0, 0], [(m22 - m11) * v, 0, 0]])
        v1 = np.array([u, q, r])
        np.testing.assert_allclose(gf[[0, 3, 4]], 1.1 * Cbar @ v1 + np.diag(pre.d)[[0, 3, 4]][:, [0, 3, 4]] @ v1 + G[[0, 3, 4]], rtol=1e-12)
