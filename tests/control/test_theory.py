"""Theorem 1: gain conditions, corrected Lemma 1 and the fixed-time bounds (auvtrack.control.fxtntsmc.theory).

The bounds are checked against the exact entry times of the scalar comparison ODEs they claim
to bound (quadrature of dt = dx / f(x), scipy quad), including cases where the paper's printed
forms fail.
"""
import json
import math

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st
from scipy.integrate import quad

from auvtrack.control.fxtntsmc import theory as th
from auvtrack.control.fxtntsmc import Params as FXTNTSMCParams

SECTION4 = dict(kappa1=0.005, kappa2=0.8, kappa3=0.6, a1=0.8, a3=0.8, a2=0.8, a4=2.0, alpha=0.6,
                sigma=0.005, varsigma1=0.05)
P4 = FXTNTSMCParams(**SECTION4)


# --------------------------------------------------------------------------- helpers

def entry_time(rhs, x0, target, t_max=1e4):
    """Time at which x' = rhs(x), x(0) = x0 > target, first reaches ``target``.

    For a scalar autonomous ODE that decreases on [target, x0] the answer is exact quadrature,
    t = integral from target to x0 of dx / (-rhs(x)), taken in log coordinates y = ln x
    (x / (-rhs(x)) dy) so that one tolerance serves x from 1e8 down to 1e-18.  No time stepping:
    stiffness near a tiny target cannot stall it.  If rhs >= 0 somewhere on the way (an
    equilibrium above the target) the target is never reached: inf.  Also inf beyond t_max.
    """
    if x0 <= target:
        return 0.0
    y0, y1 = math.log(target), math.log(x0)
    for y in np.linspace(y0, y1, 2001):
        if not rhs(math.exp(y)) < 0.0:
            return math.inf

    def dt_dy(y):
        x = math.exp(y)
        return x / -rhs(x)

    t, err = quad(dt_dy, y0, y1, epsabs=0.0, epsrel=1e-11, limit=1000)
    assert err <= 1e-9 * t, (t, err)
    return t if t <= t_max else math.inf


def s_e(z, a1, a2, a3, a4):
    return a1 * z**a2 + a3 * z**a4


def s1(s, alpha, sigma):
    """Switch (27) for s >= 0."""
    if s > sigma:
        return s**alpha
    b1 = (2 - alpha) * sigma ** (alpha - 1)
    b2 = (alpha - 1) * sigma ** (alpha - 2)
    return b1 * s + b2 * s * s


# admissible gains of Theorem 1 (phase-2 part), drawn so every condition holds with some margin
@st.composite
def admissible(draw):
    a2 = draw(st.floats(0.5, 0.97))
    alpha = draw(st.floats(0.52, min(1.9, 0.97 / a2)))
    a4 = draw(st.floats(max(1.05, 1.1 / alpha), 4.0))
    return dict(
        kappa1=draw(st.floats(1e-3, 10.0)), kappa2=draw(st.floats(1e-2, 5.0)),
        kappa3=draw(st.floats(0.51, 10.0)), a1=draw(st.floats(0.1, 5.0)), a2=a2,
        a3=draw(st.floats(0.1, 5.0)), a4=a4, alpha=alpha, sigma=draw(st.floats(1e-3, 0.5)),
        varsigma1=draw(st.floats(1e-3, 1.0)),
    )


# --------------------------------------------------------------------------- Theorem 1 conditions

def test_section4_gains_satisfy_every_condition():
    assert SECTION4["a2"] * SECTION4["alpha"] == pytest.approx(0.48)  # a2 alpha < 1
    assert SECTION4["a4"] * SECTION4["alpha"] == pytest.approx(1.2)  # b2 alpha > 1
    assert th.check_theorem1(P4) == []
    th.require_theorem1(P4)  # does not raise
    assert th.check_theorem1(SECTION4) == []  # a plain mapping of scenario keys works too
    assert th.check_theorem1(FXTNTSMCParams()) == []  # the model's defaults are Section 4's


VIOLATIONS = [  # (update from Section 4, condition text, keys named) - exactly one condition fails
    (dict(kappa1=0.0), "kappa1 > 0", ("kappa1",)),
    (dict(kappa2=-1.0), "kappa2 > 0", ("kappa2",)),
    (dict(kappa3=0.4), "kappa3 > 0.5", ("kappa3",)),
    (dict(kappa3=0.5), "kappa3 > 0.5", ("kappa3",)),
    (dict(a1=0.0), "a1 > 0", ("a1",)),
    (dict(a3=-0.1), "a3 > 0", ("a3",)),
    (dict(a2=0.4), "0.5 <= a2 < 1", ("a2",)),
    (dict(a2=1.0), "0.5 <= a2 < 1", ("a2",)),
    (dict(a4=1.0, alpha=1.2), "a4 > 1", ("a4",)),
    (dict(alpha=0.45, a4=3.0), "alpha > 0.5", ("alpha",)),
    (dict(alpha=1.3), "a2*alpha < 1", ("a2", "alpha")),
    (dict(a4=1.5), "a4*alpha > 1", ("a4", "alpha")),
    (dict(sigma=0.0), "sigma > 0", ("sigma",)),
    (dict(varsigma1=-0.05), "varsigma1 > 0", ("varsigma1",)),
]


@pytest.mark.parametrize("update, cond, keys", VIOLATIONS, ids=[v[1] + str(v[0]) for v in VIOLATIONS])
def test_each_violated_condition_is_named(update, cond, keys):
    bad = P4.model_copy(update=update)  # model_copy skips validation, like a hand-built object
    msgs = th.check_theorem1(bad)
    assert len(msgs) == 1, msgs
    (m,) = msgs
    assert f" {cond} (Theorem 1" in m
    for k in keys:
        assert f"controller.{k} = {getattr(bad, k)!r}" in m
    with pytest.raises(th.TheoremConditionError, match="Theorem 1") as exc:
        th.require_theorem1(bad)
    assert isinstance(exc.value, ValueError) and str(exc.value) == m
    b = th.fixed_time_bounds(bad)
    assert b.vacuous and any(cond in r for r in b.reasons)


def test_violations_cover_every_condition_and_use_the_exact_wording():
    assert {c for _, c, _ in VIOLATIONS} == {c[0] for c in th._CONDITIONS}
    assert len(th._CONDITIONS) == 12
    assert th.check_theorem1(P4.model_copy(update=dict(kappa3=0.4))) == [
        "controller.kappa3 = 0.4 violates kappa3 > 0.5 (Theorem 1)"]
    b1 = th.check_theorem1(P4.model_copy(update=dict(a3=0.0)))[0]
    assert "b1 > 0" in b1  # the paper's name is given alongside the scenario key


def test_require_lists_every_violation_on_one_line():
    bad = P4.model_copy(update=dict(kappa3=0.1, a2=0.3, sigma=float("nan")))
    msgs = th.check_theorem1(bad)
    assert len(msgs) == 3
    with pytest.raises(th.TheoremConditionError) as exc:
        th.require_theorem1(bad)
    assert str(exc.value) == "; ".join(msgs) and "\n" not in str(exc.value)
    assert "controller.sigma = nan violates sigma > 0" in str(exc.value)  # NaN never passes


@settings(max_examples=60)
@given(admissible())
def test_random_admissible_gains_pass(g):
    assert th.check_theorem1(g) == []
    b = th.fixed_time_bounds(g)
    assert not b.violations and all(math.isfinite(x) and x > 0 for x in (b.T1, b.T21, b.T22, b.T))


# --------------------------------------------------------------------------- Lemma 1 (corrected)

def test_lemma1_formulas():
    assert th.lemma1_time(1.0, 0.5, 2.0, 3.0, 0.5) == pytest.approx(1 / (0.5 * 0.5) + 1 / (2 * 0.5 * 2))
    assert th.lemma1_residual(1.0, 0.5, 2.0, 3.0, 0.1, 0.5) == pytest.approx(min(0.2**2, 0.1 ** (1 / 3)))
    for bad in [(0.0, 0.5, 1, 2, 0.5), (1, 1.0, 1, 2, 0.5), (1, 0.5, 1, 1.0, 0.5), (1, 0.5, 1, 2, 1.0)]:
        with pytest.raises(ValueError):
            th.lemma1_time(*bad)
    with pytest.raises(ValueError):
        th.lemma1_residual(1, 0.5, 1, 2, -1.0, 0.5)


LEMMA1_CASES = [  # m1, m2, n1, n2, m3, gamma1
    (1.0, 0.5, 1.0, 2.0, 0.1, 0.5),
    (0.3, 0.2, 5.0, 1.5, 1.0, 0.9),
    (4.0, 0.8, 0.2, 3.0, 0.01, 0.1),
    (0.05, 0.5, 0.5, 2.0, 1e-4, 0.5),  # the shape of (42): m2 = 1/2, n2 = 2
]


@pytest.mark.parametrize("m1, m2, n1, n2, m3, gamma1", LEMMA1_CASES)
def test_lemma1_by_integration_is_fixed_time(m1, m2, n1, n2, m3, gamma1):
    T = th.lemma1_time(m1, m2, n1, n2, gamma1)
    R = th.lemma1_residual(m1, m2, n1, n2, m3, gamma1)

    def rhs(v):
        return -m1 * v**m2 - n1 * v**n2 + m3

    assert rhs(R) < 0  # V decreases on the boundary: the set is invariant
    v0s = np.logspace(-2, 8, 11)
    times = [entry_time(rhs, v0, R) for v0 in v0s]
    assert max(times) <= T  # never exceeds the bound
    assert all(np.diff(times) >= -1e-9)  # monotone in V0 ...
    # ... and saturating: from V0 on, at most V0^(1-n2) / (gamma1 n1 (n2-1)) remains to be gained
    for v0, t in zip(v0s, times):
        if v0 > R:
            assert times[-1] - t <= v0 ** (1 - n2) / (gamma1 * n1 * (n2 - 1)) + 1e-6
    assert times[-1] - times[-3] <= 1e-3 * T + 1e-6 * T  # 1e6 -> 1e8 adds almost nothing


def test_lemma1_test_is_discriminating():
    """Without the V^n2 term the entry time grows without bound: the check above would fail."""
    m1, m2, m3, R = 1.0, 0.5, 0.1, 0.04

    def rhs(v):
        return -m1 * v**m2 + m3

    times = [entry_time(rhs, v0, R, t_max=1e6) for v0 in (1e2, 1e4, 1e6)]
    assert times[2] > 10 * times[0]
    assert times[2] > th.lemma1_time(m1, m2, 1.0, 2.0, 0.5)


@settings(max_examples=25)
@example(1.0, 0.109375, 1.0, 2.0, 0.0078125, 0.5, 0.0)  # R = 3e-17: stiff at the target (once failed CI)
@given(st.floats(0.05, 5), st.floats(0.1, 0.9), st.floats(0.05, 5), st.floats(1.2, 3.0),
       st.floats(1e-3, 2.0), st.floats(0.05, 0.95), st.floats(-2, 8))
def test_lemma1_bound_holds_for_random_systems(m1, m2, n1, n2, m3, gamma1, log_v0):
    T = th.lemma1_time(m1, m2, n1, n2, gamma1)
    R = th.lemma1_residual(m1, m2, n1, n2, m3, gamma1)
    t = entry_time(lambda v: -m1 * v**m2 - n1 * v**n2 + m3, 10.0**log_v0, R, t_max=2 * T)
    assert t <= T


def test_printed_lemma1_bound_is_wrong():
    """(6) as printed has 1/(n1 gamma1 (1 - n2)) < 0; integration exceeds it (ERRATA 15)."""
    m1, m2, n1, n2, m3, g = 1.0, 0.5, 1.0, 2.0, 1e-6, 0.5
    printed = 1 / (m1 * g * (1 - m2)) + 1 / (n1 * g * (1 - n2))  # = 2
    R = th.lemma1_residual(m1, m2, n1, n2, m3, g)
    t = entry_time(lambda v: -m1 * v**m2 - n1 * v**n2 + m3, 1e8, R)
    assert printed < t <= th.lemma1_time(m1, m2, n1, n2, g)
    assert t == pytest.approx(4 * math.pi / (3 * math.sqrt(3)), rel=2e-2)  # int_0^inf dV/(V^0.5 + V^2)


# --------------------------------------------------------------------------- T1, (42)-(44)

def test_t1_is_lemma1_with_the_constants_of_42():
    b = th.fixed_time_bounds(P4, w_norm=0.7, gamma1=0.3)
    assert b.T1 == pytest.approx(2 / (b.zeta1 * 0.3) + 1 / (b.zeta2 * 0.3))
    assert b.T1 == pytest.approx(th.lemma1_time(b.zeta1, 0.5, b.zeta2, 2.0, 0.3))
    lam = min((b.zeta3 / (b.zeta1 * 0.7)) ** 2, (b.zeta3 / (b.zeta2 * 0.7)) ** 0.5)  # (44)
    assert b.Lambda == pytest.approx(lam)
    assert b.p == pytest.approx(math.sqrt(2 * lam))
    k = 0.75 * b.lam2 ** (4 / 3) + 0.75 / b.lam1**4
    assert b.zeta3 == pytest.approx(0.5 * 0.05**2 + 3 * (0.49 + k * 0.7**4))  # with varsigma1, not zeta1


def test_section4_t1_exceeds_283_s():
    """ERRATA 15: zeta1 <= sqrt2 kappa1 = 0.00707, so T1 >= 2/(zeta1 gamma1) > 283 s."""
    assert math.sqrt(2) * 0.005 == pytest.approx(0.00707, abs=1e-5)
    for g in np.concatenate([np.linspace(0.001, 0.999, 50), [1 - 1e-9, 1e-9]]):
        b = th.fixed_time_bounds(P4, gamma1=float(g))
        assert b.zeta1 == pytest.approx(math.sqrt(2) * 0.005)
        assert b.T1 > 283.0 and b.T1_printed > 283.0
        assert b.T1_is_lower_bound
        for w in (0.01, 0.1, 1.0, 10.0):  # a known ideal-weight norm can only make it longer
            assert th.fixed_time_bounds(P4, gamma1=float(g), w_norm=w).T1 >= b.T1
    b = th.fixed_time_bounds(P4)  # defaults gamma1 = g1 = g2 = 0.5
    assert b.T1 == pytest.approx(4 / (math.sqrt(2) * 0.005) + 2 / (2 / 3 * 0.8))
    assert b.T1_printed == pytest.approx(4 / (math.sqrt(2) * 0.005) + 2 / 3.2)


@settings(max_examples=50)
@given(st.floats(1e-6, 1 - 1e-6, exclude_min=True, exclude_max=True))
def test_section4_t1_exceeds_283_s_for_any_gamma1(g):
    assert th.fixed_time_bounds(P4, gamma1=g).T1 > 283.0


def test_printed_zeta2_breaks_42_and_the_corrected_one_holds():
    """Lemma 3 (10) with n = 6 terms: sum x_j^2 >= (2/3) V^2, not 4 V^2."""
    b = th.fixed_time_bounds(P4)
    c = th._young_c(b.lam1, b.lam2)
    assert c == pytest.approx(0.8)  # lam1, lam2 chosen so that min{kappa2, c} = kappa2
    assert b.zeta2_printed == pytest.approx(min(4 * 0.8, 4 - 9 * b.lam1 ** (4 / 3) - 1 / b.lam2**4))
    s = w = np.ones(3)  # S_i = |W~_i| = 1: V = 3
    V = 0.5 * (s @ s + w @ w)
    have = 0.8 * np.sum(s**4) + c * np.sum(w**4)
    assert b.zeta2_printed * V**2 > have  # the printed (42) claims more decay than there is
    rng = np.random.default_rng(0)
    for _ in range(2000):
        s, w = rng.normal(size=3) * 10 ** rng.uniform(-3, 3), np.abs(rng.normal(size=3)) * 10 ** rng.uniform(-3, 3)
        V = 0.5 * (s @ s + w @ w)
        assert 0.8 * np.sum(s**4) + c * np.sum(w**4) >= b.zeta2 * V**2 * (1 - 1e-12)
        wn = 0.3  # zeta1's step: kappa1 |S_i| + 2 |W|^2 |W~_i| >= zeta1 V^(1/2)
        z1 = th.fixed_time_bounds(P4, w_norm=wn).zeta1
        assert 0.005 * np.sum(np.abs(s)) + 2 * wn**2 * np.sum(w) >= z1 * math.sqrt(V) * (1 - 1e-12)


def test_lam_choice():
    b = th.fixed_time_bounds(P4, w_norm=1.0)
    assert b.lam2 == pytest.approx(1 / b.lam1)  # stationary point of zeta3 on the budget
    k = 0.75 * b.lam2 ** (4 / 3) + 0.75 / b.lam1**4
    for d1 in np.linspace(0.01, 0.199, 40):  # any other split of the budget 1 - c = 0.2 is worse
        l1, l2 = (d1 / 2.25) ** 0.75, (4 * (0.2 - d1)) ** -0.25
        assert th._young_c(l1, l2) == pytest.approx(0.8)
        assert 0.75 * l2 ** (4 / 3) + 0.75 / l1**4 >= k * (1 - 1e-9)
    # given constants are kept; the other one is chosen
    b1 = th.fixed_time_bounds(P4, lam1=0.1)
    assert b1.lam1 == 0.1 and th._young_c(b1.lam1, b1.lam2) == pytest.approx(0.8)
    b2 = th.fixed_time_bounds(P4, lam2=3.0)
    assert b2.lam2 == 3.0 and th._young_c(b2.lam1, b2.lam2) == pytest.approx(0.8)
    big = th.fixed_time_bounds(P4.model_copy(update=dict(kappa2=5.0)))
    assert 0.998 < th._young_c(big.lam1, big.lam2) < 1 and any("kappa2 >= 1" in n for n in big.notes)
    # lam1, lam2 that leave no V^2 decay: T1 is infinite and the bounds say so
    bad = th.fixed_time_bounds(P4, lam1=0.9, lam2=1.0)
    assert 4 - 9 * 0.9 ** (4 / 3) - 1 < 0
    assert math.isinf(bad.T1) and bad.vacuous and any("V^2 term" in r for r in bad.reasons)


# --------------------------------------------------------------------------- T21, (45)-(48)

def test_t21_algebra_and_section4_value():
    a1, a2, a3, a4, al, g1 = 0.8, 0.8, 0.8, 2.0, 0.6, 0.5
    lam = (a4 - a2) / (1 - a2 * al)
    assert (1 - a2 * al) * (lam * al - 1) == pytest.approx(a4 * al - 1)
    penultimate = (1 / (g1 * (1 - a2 * al))) * (1 / (a3**al * (lam * al - 1)) + 1 / a1**al)
    assert th.t21_bound(a1, a2, a3, a4, al, g1) == pytest.approx(penultimate)
    assert th.fixed_time_bounds(P4).T21 == pytest.approx(15.8298, abs=1e-4)


@settings(max_examples=100)
@given(admissible(), st.floats(0.05, 0.95))
def test_t21_last_step_algebra(g, g1):
    a1, a2, a3, a4, al = (g[k] for k in ("a1", "a2", "a3", "a4", "alpha"))
    lam = (a4 - a2) / (1 - a2 * al)
    assert (1 - a2 * al) * (lam * al - 1) == pytest.approx(a4 * al - 1, rel=1e-12, abs=1e-12)
    pen = (1 / (g1 * (1 - a2 * al))) * (1 / (a3**al * (lam * al - 1)) + 1 / a1**al)
    assert th.t21_bound(a1, a2, a3, a4, al, g1) == pytest.approx(pen, rel=1e-12)


@pytest.mark.parametrize("gains", [
    dict(a1=0.8, a2=0.8, a3=0.8, a4=2.0, alpha=0.6),  # Section 4
    dict(a1=0.2, a2=0.5, a3=3.0, a4=1.5, alpha=1.2),
    dict(a1=2.0, a2=0.95, a3=0.3, a4=4.0, alpha=0.55),
])
def test_t21_bounds_the_comparison_ode_46(gains):
    """z' = -g1 (a1 z^a2 + a3 z^a4)^alpha from z0 up to 1e8 reaches mu (-> 0) within T21."""
    a1, a2, a3, a4, al = (gains[k] for k in ("a1", "a2", "a3", "a4", "alpha"))
    g1 = 0.5
    T21 = th.t21_bound(a1, a2, a3, a4, al, g1)
    times = [entry_time(lambda z: -g1 * s_e(z, a1, a2, a3, a4) ** al, z0, 1e-10) for z0 in np.logspace(-4, 8, 7)]
    assert max(times) <= T21
    assert times[-1] - times[-2] <= 0.05 * T21  # fixed time: 1e6 -> 1e8 adds little


@settings(max_examples=25)
@given(admissible(), st.floats(0.1, 0.9), st.floats(-3, 8))
def test_t21_bounds_random_comparison_odes(g, g1, log_z0):
    a1, a2, a3, a4, al = (g[k] for k in ("a1", "a2", "a3", "a4", "alpha"))
    T21 = th.t21_bound(a1, a2, a3, a4, al, g1)
    t = entry_time(lambda z: -g1 * s_e(z, a1, a2, a3, a4) ** al, 10.0**log_z0, 1e-9, t_max=2 * T21)
    assert t <= T21


# --------------------------------------------------------------------------- T22, (49)-(52)

def test_51_drops_a_negative_beta2():
    """beta2 < 0 for alpha < 1: S1(S_e) >= beta1 S_e, used by the printed (51), is false."""
    al, sg = 0.6, 0.005
    b1, b2 = (2 - al) * sg ** (al - 1), (al - 1) * sg ** (al - 2)
    assert b2 < 0
    assert s1(sg, al, sg) < b1 * sg  # printed (51) fails at S_e = sigma
    assert th.switch_slope(al, sg) == pytest.approx(b1 + b2 * sg) == pytest.approx(sg ** (al - 1))
    for s in np.linspace(1e-9, sg, 200):  # the corrected slope holds on the whole inner region
        assert s1(s, al, sg) >= th.switch_slope(al, sg) * s * (1 - 1e-12)
    for al in (1.0, 1.5, 1.9):  # beta2 >= 0: beta1 itself is the least slope
        assert th.switch_slope(al, sg) == pytest.approx((2 - al) * sg ** (al - 1))


def test_t22_section4_values():
    b = th.fixed_time_bounds(P4)
    assert b.beta1 == pytest.approx(1.4 * 0.005**-0.4) and b.beta2 == pytest.approx(-0.4 * 0.005**-1.4)
    assert b.beta_eff == pytest.approx(0.005**-0.4)
    form = 1 / (0.8 * 0.2) + 1 / (0.8 * 1.0)
    assert b.T22 == pytest.approx(form / (0.5 * 0.005**-0.4))
    assert b.T22_printed == pytest.approx(form / (0.5 * 1.4 * 0.005**-0.4))
    assert b.T22 == pytest.approx(1.8017, abs=1e-4) and b.T22_printed == pytest.approx(1.2869, abs=1e-4)


@pytest.mark.parametrize("gains", [
    dict(a1=0.8, a2=0.8, a3=0.8, a4=2.0, alpha=0.6, sigma=0.005),  # Section 4
    dict(a1=0.5, a2=0.99, a3=0.5, a4=1.2, alpha=0.51, sigma=1.0),
    dict(a1=1.0, a2=0.5, a3=1.0, a4=2.0, alpha=1.5, sigma=0.1),
])
def test_t22_bounds_the_comparison_ode_50(gains):
    """z' = -g2 (beta1 S_e + beta2 S_e^2) on S_e <= sigma, from S_e = sigma to 0, within T22."""
    a1, a2, a3, a4, al, sg = (gains[k] for k in ("a1", "a2", "a3", "a4", "alpha", "sigma"))
    g2 = 0.5
    zs = th._z_of_se(sg, a1, a2, a3, a4)
    assert s_e(zs, a1, a2, a3, a4) == pytest.approx(sg)
    t = entry_time(lambda z: -g2 * s1(s_e(z, a1, a2, a3, a4), al, sg), zs, 1e-12)
    assert t <= th.t22_bound(a1, a2, a3, a4, al, sg, g2)


@settings(max_examples=25)
@given(admissible(), st.floats(0.1, 0.9))
def test_t22_bounds_random_comparison_odes(g, g2):
    a1, a2, a3, a4, al, sg = (g[k] for k in ("a1", "a2", "a3", "a4", "alpha", "sigma"))
    zs = th._z_of_se(sg, a1, a2, a3, a4)
    T22 = th.t22_bound(a1, a2, a3, a4, al, sg, g2)
    t = entry_time(lambda z: -g2 * s1(s_e(z, a1, a2, a3, a4), al, sg), zs, 1e-12, t_max=2 * T22)
    assert t <= T22


# --------------------------------------------------------------------------- T2 = T21 + T22

def test_printed_t2_max_is_exceeded_on_the_sliding_manifold():
    """On S = 0 (any p >= 0 allows it), z' = -S1(S_e(z)) crosses both regions in turn.

    For these admissible gains the time from z0 = 1e4 to 0 exceeds max{T21, T22} even with
    g1 = g2 = 0.9, so the printed T2 = max{...} is not a bound; T21 + T22 is.
    """
    g = dict(SECTION4, a1=1.0, a2=0.95, a3=1.0, a4=3.0, alpha=0.6, sigma=0.01)
    assert th.check_theorem1(g) == []
    b = th.fixed_time_bounds(g, g1=0.9, g2=0.9)
    t = entry_time(lambda z: -s1(s_e(z, 1.0, 0.95, 1.0, 3.0), 0.6, 0.01), 1e4, 1e-12)
    assert b.T2_printed == max(b.T21, b.T22)
    assert b.T2_printed < t <= b.T2 == b.T21 + b.T22


@settings(max_examples=20)
@given(admissible(), st.floats(0.1, 0.9), st.floats(0.1, 0.9), st.floats(-2, 6))
def test_t2_bounds_the_piecewise_comparison_ode(g, g1, g2, log_z0):
    a1, a2, a3, a4, al, sg = (g[k] for k in ("a1", "a2", "a3", "a4", "alpha", "sigma"))

    def rhs(z):
        s = s_e(z, a1, a2, a3, a4)
        return -(g1 if s > sg else g2) * s1(s, al, sg)

    b = th.fixed_time_bounds(g, g1=g1, g2=g2)
    assert entry_time(rhs, 10.0**log_z0, 1e-12, t_max=2 * b.T2) <= b.T2


# --------------------------------------------------------------------------- residual and vacuity

def test_section4_is_vacuous_within_a_simulation_horizon():
    b = th.fixed_time_bounds(P4, horizon=100.0)
    assert b.vacuous and not b.violations
    assert any("T1" in r and "horizon 100 s" in r for r in b.reasons)
    rep = b.report()
    assert "VACUOUS" in rep and "LOWER BOUND" in rep
    for eq in ("(42)", "(43)", "(48)", "(52)", "(44)"):
        assert eq in rep
    d = b.to_dict()
    json.dumps(d, allow_nan=False)
    assert d["vacuous"] is True and d["T1"] == pytest.approx(b.T1) and d["zeta3"] is None


def test_vacuous_when_a_bound_is_infinite_and_json_says_inf():
    b = th.fixed_time_bounds(P4, w_norm=0.0)  # zeta1 = min{..., 0} = 0
    assert b.zeta1 == 0 and math.isinf(b.T1) and math.isinf(b.T) and b.vacuous
    assert any("zeta1" in r for r in b.reasons)
    d = b.to_dict()
    assert d["T1"] == "inf" and json.loads(json.dumps(d, allow_nan=False))["T"] == "inf"
    bad = th.fixed_time_bounds(P4.model_copy(update=dict(alpha=1.3)))  # a2 alpha = 1.04
    assert math.isinf(bad.T21) and bad.vacuous and len(bad.reasons) >= 2
    json.dumps(bad.to_dict(), allow_nan=False)


def test_certified_case_and_unknown_weight_norm():
    fast = dict(SECTION4, kappa1=50.0, kappa2=0.9)
    ok = th.fixed_time_bounds(fast, w_norm=1.0, horizon=100.0, p=1e-3)
    assert not ok.vacuous and ok.reasons == [] and not ok.T1_is_lower_bound
    assert ok.T <= 100.0 and ok.mu is not None and math.tanh(ok.mu) < 0.99
    assert "OK:" in ok.report() and "VACUOUS" not in ok.report()
    unk = th.fixed_time_bounds(fast, horizon=1e4)  # w_norm unknown: not vacuous, not certified either
    assert not unk.vacuous and unk.T1_is_lower_bound and unk.Lambda is None and unk.mu1 is None
    assert "NOT CERTIFIED" in unk.report()


def test_residual_set_covering_the_envelope_is_vacuous():
    b = th.fixed_time_bounds(P4, w_norm=1.0, horizon=1e5)  # zeta3 ~ 3e3: |S| <= p ~ 15
    assert b.p > 1 and b.mu1 > b.z_sigma and b.mu == b.mu1
    assert (1 - 0.5) * s_e(b.mu1, 0.8, 0.8, 0.8, 2.0) ** 0.6 == pytest.approx(b.p)  # definition below (45)
    assert b.vacuous and any("whole envelope" in r for r in b.reasons)


def test_mu2_definition_below_49():
    g = dict(SECTION4, kappa1=50.0)
    b = th.fixed_time_bounds(g, w_norm=0.05, p=1e-4)
    s = s_e(b.mu2, 0.8, 0.8, 0.8, 2.0)
    assert s < 0.005 and (1 - 0.5) * s1(s, 0.6, 0.005) == pytest.approx(1e-4)
    assert b.mu == b.mu2  # mu1 < z_sigma: the inner phase sets the residual


def test_bad_proof_constants_raise():
    for kw in (dict(gamma1=1.0), dict(gamma1=0.0), dict(g1=1.5), dict(g2=-0.1), dict(lam1=0.0),
               dict(lam2=-1.0), dict(w_norm=-1.0), dict(w_norm=[1.0, 2.0]), dict(horizon=0.0), dict(p=-1.0)):
        with pytest.raises(ValueError):
            th.fixed_time_bounds(P4, **kw)


def test_w_norm_per_axis():
    b = th.fixed_time_bounds(P4, w_norm=[0.01, 1.0, 2.0])
    assert b.zeta1 == pytest.approx(min(math.sqrt(2) * 0.005, 2 * math.sqrt(2) * 0.01**2))
    k = 0.75 * b.lam2 ** (4 / 3) + 0.75 / b.lam1**4
    assert b.zeta3 == pytest.approx(0.5 * 0.05**2 + sum(w**2 + k * w**4 for w in (0.01, 1.0, 2.0)))


def test_nonsingular_surface_caveat():
    assert any("z_switch" in n for n in th.fixed_time_bounds(P4).notes)
    printed = th.fixed_time_bounds(P4.model_copy(update=dict(surface="printed")))
    assert not any("z_switch" in n for n in printed.notes)


@given(st.floats(1e-6, 50.0), st.floats(0.05, 5.0), st.floats(0.1, 0.99), st.floats(0.05, 5.0), st.floats(1.01, 3.0))
def test_theory_surface_is_the_compiled_printed_surface(z, a1, a2, a3, a4):
    """The root-finding S_e of eq. (28) equals fxtntsmc.surface (printed) for z > 0."""
    from auvtrack.control.fxtntsmc import surface

    got = th._se(z, a1, a2, a3, a4)
    assert got == pytest.approx(surface(z, a1, a2, a3, a4, True, 0.0, 0.0)[0], rel=1e-12, abs=0)
    assert th._se(0.0, a1, a2, a3, a4) == 0.0
