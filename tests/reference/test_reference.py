"""Reference trajectories: exact derivatives, paper helix, path geometry, ends, packing, specs."""
import json
import math

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st
from scipy.interpolate import CubicSpline

from auvtrack.reference import (
    REFERENCES,
    Circle,
    Helix,
    Lawnmower,
    Line,
    Waypoints,
    build_reference,
    eval_reference,
)
from auvtrack.reference.kernel import HEADER, SEG

EPS = np.finfo(float).eps


def _fd_check(ref, t, d2, d3, d4, scale_p, scale_v):
    """Central differences of p and v at t against v and a.

    ``d2, d3, d4`` bound the 2nd, 3rd, 4th derivatives of p near t; ``scale_p, scale_v`` bound
    the magnitudes of the terms summed to evaluate p and v.  Error bound: truncation
    h^2/6 * (3rd derivative of the differenced quantity), round-off 8 eps scale / h of the two
    evaluations, where ``scale`` also counts the rounding of the local time / trig argument (as if
    evaluated at a time off by 2 eps |t|: 2 eps |t| times the derivative), and eps |t| * (next
    derivative) because the centre (t1 + t0) / 2 of the actual floats t1 = t + h, t0 = t - h is
    not exactly t (the divisor t1 - t0 is exact).  h balances truncation against round-off.
    """
    scale_p = scale_p + 0.25 * abs(t) * scale_v  # 8 eps * (|t| v / 4) = 2 eps |t| v
    scale_v = scale_v + 0.25 * abs(t) * d2
    for k, d, dc, scale in ((0, d3, d2, scale_p), (1, d4, d3, scale_v)):
        h = float(np.clip((24 * EPS * scale / max(d, 1e-300)) ** (1 / 3), 1e-6, 1e-2))
        t1, t0 = t + h, t - h
        fd = (ref.evaluate(t1)[k] - ref.evaluate(t0)[k]) / (t1 - t0)
        exact = ref.evaluate(t)[k + 1]
        H = (t1 - t0) / 2
        tol = H * H / 6 * d + 8 * EPS * scale / H + EPS * abs(t) * dc
        err = np.abs(fd - exact)
        assert np.all(err <= tol), f"derivative {k + 1}: |fd - exact| = {err} > {tol} (t={t}, h={H})"


def _pack_eval(ref_p, t):
    out = np.zeros((3, 3))
    eval_reference(ref_p, float(t), out)
    return out


# --- helix / circle / line ---------------------------------------------------------------------

def test_helix_default_is_the_paper_reference_exactly():
    """Section 4: eta_d = [4 cos(0.1 t), 4 sin(0.1 t), -0.1 t] bit for bit; derivatives exact."""
    h = Helix()
    ts = np.concatenate([np.linspace(0.0, 600.0, 2401), [1e-9, 123.456, 599.999]])
    p, v, a = h.evaluate(ts)
    want = np.array([[4 * math.cos(0.1 * t), 4 * math.sin(0.1 * t), -0.1 * t] for t in ts])
    assert np.array_equal(p, want)
    dwant = np.array([[-0.4 * math.sin(0.1 * t), 0.4 * math.cos(0.1 * t), -0.1] for t in ts])
    np.testing.assert_allclose(v, dwant, rtol=0, atol=4e-16)
    awant = np.array([[-0.04 * math.cos(0.1 * t), -0.04 * math.sin(0.1 * t), 0.0] for t in ts])
    np.testing.assert_allclose(a, awant, rtol=0, atol=1e-17)


radii = st.floats(0.1, 100.0)
omegas = st.floats(-2.0, 2.0).filter(lambda w: abs(w) > 1e-3)
coords = st.floats(-1000.0, 1000.0)
phases = st.floats(-math.pi, math.pi)


@settings(max_examples=80)
@given(radii, omegas, st.floats(-2.0, 2.0), coords, coords, coords, phases, st.floats(-100.0, 1000.0))
def test_helix_derivatives_by_finite_differences(R, w, climb, cx, cy, cz, ph, t):
    h = Helix(radius=R, omega=w, climb=climb, center=(cx, cy, cz), phase=ph)
    scale_p = max(abs(cx), abs(cy), abs(cz)) + R + abs(climb) * (abs(t) + 1)
    _fd_check(h, t, R * w * w, R * abs(w) ** 3, R * w**4, scale_p, R * abs(w) + abs(climb))


@settings(max_examples=40)
@given(radii, omegas, coords, coords, coords, phases, st.floats(-100.0, 1000.0))
def test_circle_geometry_and_derivatives(R, w, depth, cx, cy, ph, t):
    c = Circle(radius=R, omega=w, depth=depth, center=(cx, cy), phase=ph)
    p, v, a = c.evaluate(t)
    assert p[2] == depth and v[2] == 0.0 and a[2] == 0.0
    rel = p[:2] - (cx, cy)
    scale = abs(cx) + abs(cy) + R
    assert abs(np.hypot(*rel) - R) <= 8 * EPS * scale
    np.testing.assert_allclose(np.hypot(*v[:2]), R * abs(w), rtol=1e-12)
    np.testing.assert_allclose(a[:2], -w * w * rel, rtol=0, atol=16 * EPS * scale * w * w)
    np.testing.assert_allclose(rel, [R * math.cos(w * t + ph), R * math.sin(w * t + ph)],
                               rtol=0, atol=16 * EPS * scale + 4 * EPS * R * abs(w * t))
    _fd_check(c, t, R * w * w, R * abs(w) ** 3, R * w**4, scale, R * abs(w))


def test_circle_is_a_flat_helix():
    c = Circle(radius=3.0, omega=-0.2, depth=7.5, center=(1.0, -2.0), phase=0.4)
    h = Helix(radius=3.0, omega=-0.2, climb=0.0, center=(1.0, -2.0, 7.5), phase=0.4)
    assert np.array_equal(c.pack(), h.pack())


def test_zero_rate_circle_is_a_fixed_point():
    p, v, a = Circle(radius=2.0, omega=0.0, depth=1.0, phase=0.5).evaluate(np.array([0.0, 3.0, -7.0]))
    np.testing.assert_allclose(p, [[2 * math.cos(0.5), 2 * math.sin(0.5), 1.0]] * 3, rtol=1e-15)
    assert not v.any() and not a.any()


@settings(max_examples=40)
@given(st.tuples(coords, coords, coords), st.tuples(*[st.floats(-5.0, 5.0)] * 3), st.floats(-100.0, 1000.0))
def test_line(start, vel, t):
    p, v, a = Line(start=start, velocity=vel).evaluate(t)
    np.testing.assert_allclose(p, np.add(start, np.multiply(vel, t)), rtol=0, atol=4 * EPS * 6000)
    assert np.array_equal(v, vel) and not a.any()


# --- lawnmower ---------------------------------------------------------------------------------

mowers = st.builds(
    Lawnmower,
    start=st.tuples(st.floats(-100.0, 100.0), st.floats(-100.0, 100.0)),
    heading=st.floats(-math.pi, math.pi),
    leg_length=st.floats(1.0, 100.0),
    spacing=st.floats(0.5, 50.0),
    legs=st.integers(1, 6),
    speed=st.floats(0.1, 3.0),
    depth=st.floats(0.0, 100.0),
    first_turn=st.sampled_from(["right", "left"]),
    end=st.sampled_from(["continue", "hold"]),
)


def _mower_scales(m, t):
    R, V = m.turn_radius, m.speed
    scale_p = 200 + m.leg_length + m.legs * m.spacing + m.depth + V * (abs(t) + 1)
    return V**2 / R, V**3 / R**2, V**4 / R**3, scale_p, V


@settings(max_examples=80)
@given(mowers, st.floats(0.0, 1.0))
def test_lawnmower_derivatives_by_finite_differences(m, frac):
    t = frac * 1.2 * m.duration
    assume(np.min(np.abs(m.breakpoints - t)) > 1e-2 + 1e-9 * t)  # no difference across a joint
    _fd_check(m, t, *_mower_scales(m, t))


@settings(max_examples=40)
@given(mowers)
def test_lawnmower_is_c1_at_every_joint(m):
    """Position and velocity continuous at every joint; |a| bounded by speed^2 / turn radius."""
    joints = m.breakpoints[1:]  # t = 0: starts from the held start point (velocity step)
    if m.end == "hold":
        joints = joints[:-1]  # the hold deliberately stops at the end (velocity step)
    assert joints.size == 2 * m.legs - 2
    left = m.evaluate(np.nextafter(joints, -np.inf))
    right = m.evaluate(joints)
    scale = 200 + m.leg_length + m.legs * m.spacing + m.depth
    np.testing.assert_allclose(left[0], right[0], rtol=0, atol=64 * EPS * scale)
    # velocity: rounding of the local time (~eps t) times the turn rate speed / radius
    vtol = 64 * EPS * m.speed * (1 + m.speed / m.turn_radius * m.duration)
    np.testing.assert_allclose(left[1], right[1], rtol=0, atol=vtol)
    ts = np.linspace(0.0, m.duration, 2001, endpoint=False)  # "hold" stops at t = duration
    p, v, a = m.evaluate(ts)
    np.testing.assert_allclose(np.linalg.norm(v, axis=1), m.speed, rtol=1e-12)  # constant speed
    assert np.all(np.linalg.norm(a, axis=1) <= m.speed**2 / m.turn_radius * (1 + 1e-12))
    assert np.all(p[:, 2] == m.depth) and not v[:, 2].any() and not a[:, 2].any()


@pytest.mark.parametrize("first_turn", ["right", "left"])
def test_lawnmower_visits_every_leg_endpoint(first_turn):
    L, S, V, psi, n = 40.0, 6.0, 1.5, 0.7, 5
    m = Lawnmower(start=(3.0, -4.0), heading=psi, leg_length=L, spacing=S, legs=n, speed=V,
                  depth=12.0, first_turn=first_turn)
    d = np.array([math.cos(psi), math.sin(psi)])
    off = np.array([-math.sin(psi), math.cos(psi)]) * (1 if first_turn == "right" else -1)
    period = L / V + math.pi * (S / 2) / V
    for i in range(n):
        a0 = np.array([3.0, -4.0]) + i * S * off
        ends = [a0, a0 + L * d] if i % 2 == 0 else [a0 + L * d, a0]
        for t, want in ((i * period, ends[0]), (i * period + L / V, ends[1])):
            p, v, _ = m.evaluate(t)
            np.testing.assert_allclose(p, [*want, 12.0], rtol=0, atol=1e-12)
            np.testing.assert_allclose(v[:2], V * d * (1 if i % 2 == 0 else -1), rtol=0, atol=1e-12)
        mid = m.evaluate(i * period + L / (2 * V))[0]  # straight between them
        np.testing.assert_allclose(mid[:2], (ends[0] + ends[1]) / 2, rtol=0, atol=1e-12)
    assert m.duration == pytest.approx(n * L / V + (n - 1) * math.pi * S / 2 / V, rel=1e-15)
    # starboard of heading psi in NED is (-sin psi, cos psi): a right first turn stacks legs there
    if first_turn == "right":
        assert np.dot(m.evaluate(period)[0][:2] - (3.0, -4.0), [-math.sin(psi), math.cos(psi)]) > 0


def test_lawnmower_ends():
    m = Lawnmower(legs=3, leg_length=20.0, spacing=4.0, speed=2.0)
    T = m.duration
    pe, ve, _ = m.evaluate(T)
    p, v, a = m.evaluate(np.array([T + 1.0, T + 1e6]))
    np.testing.assert_allclose(p, [pe + ve * 1.0, pe + ve * 1e6], rtol=1e-12)
    assert np.array_equal(v, [ve, ve]) and not a.any()
    h = Lawnmower(legs=3, leg_length=20.0, spacing=4.0, speed=2.0, end="hold")
    p, v, a = h.evaluate(np.array([T, T + 1.0, T + 1e6]))
    np.testing.assert_allclose(p, [pe] * 3, rtol=0, atol=1e-12)
    assert not v.any() and not a.any()
    p, v, a = m.evaluate(np.array([-1e-9, -5.0, -1e6]))  # before the start: hold at rest
    assert np.array_equal(p, [[0.0, 0.0, 5.0]] * 3) and not v.any() and not a.any()


def test_single_leg_lawnmower_is_a_line():
    m = Lawnmower(legs=1, leg_length=10.0, speed=0.5, heading=math.pi / 2, depth=3.0)
    p, v, a = m.evaluate(np.array([0.0, 20.0, 40.0]))
    np.testing.assert_allclose(p, [[0, 0, 3], [0, 10, 3], [0, 20, 3]], atol=1e-14)
    assert m.duration == 20.0


# --- waypoints ---------------------------------------------------------------------------------

def _points(min_gap=0.5):
    # coordinates in metres to the micrometre: a waypoint at 1e-302 m only exercises subnormal
    # arithmetic, where the bounds' relative rounding unit does not apply
    pt = st.tuples(*[st.floats(-50.0, 50.0).map(lambda v: round(v, 6))] * 3)

    def far_apart(ps):
        return all(np.linalg.norm(np.subtract(a, b)) >= min_gap for a, b in zip(ps, ps[1:]))

    return st.lists(pt, min_size=2, max_size=8).filter(far_apart)


@settings(max_examples=60)
@given(_points(), st.floats(0.2, 3.0), st.floats(0.0, 1.0))
def test_waypoints_derivatives_by_finite_differences(pts, speed, frac):
    w = Waypoints(points=pts, speed=speed)
    t = frac * w.duration
    assume(np.min(np.abs(w.times - t)) > 1e-2)  # the third derivative jumps at knots
    sp = CubicSpline(w.times, np.array(pts), bc_type="natural")  # independent implementation
    c = np.abs(sp.c[::-1])  # |c0|..|c3| per piece and axis, local time s in [0, dt]
    dt = np.diff(w.times)[:, None]
    scale_p = 1 + float(np.max(c[0] + c[1] * dt + c[2] * dt**2 + c[3] * dt**3))
    scale_v = 1 + float(np.max(c[1] + 2 * c[2] * dt + 3 * c[3] * dt**2))
    d2 = float(np.max(2 * c[2] + 6 * c[3] * dt))
    d3 = float(np.max(6 * c[3]))
    p, v, a = w.evaluate(t)
    np.testing.assert_allclose(p, sp(t), rtol=0, atol=16 * EPS * scale_p)
    np.testing.assert_allclose(v, sp(t, 1), rtol=0, atol=16 * EPS * scale_v)
    np.testing.assert_allclose(a, sp(t, 2), rtol=0, atol=16 * EPS * (d2 + d3 * float(dt.max())))
    _fd_check(w, t, d2, d3, 0.0, scale_p, scale_v)


@settings(max_examples=60)
@given(_points(), st.floats(0.2, 3.0), st.sampled_from(["continue", "hold"]))
def test_waypoints_pass_through_every_point_and_are_c2(pts, speed, end):
    w = Waypoints(points=pts, speed=speed, end=end)
    P = np.array(pts)
    times = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(P, axis=0), axis=1)) / speed])
    np.testing.assert_allclose(w.times, times, rtol=1e-15)
    p, v, a = w.evaluate(times)
    assert np.array_equal(p[:-1], P[:-1])  # each piece starts exactly at its waypoint
    np.testing.assert_allclose(p[-1], P[-1], rtol=0, atol=1e-10)
    tol = 1e-12 * (1 + float(np.abs(a).max()))  # natural ends: zero acceleration up to round-off
    assert np.abs(a[0]).max() <= tol and (end == "hold" or np.abs(a[-1]).max() <= tol)
    inner = times[1:-1] if end == "hold" else times[1:]
    left = w.evaluate(np.nextafter(inner, -np.inf))
    right = w.evaluate(inner)
    scale = 1 + float(np.abs(v).max()) + float(np.abs(a).max())
    for k in range(3):  # C2 at the knots (and into the tangent continuation)
        np.testing.assert_allclose(left[k], right[k], rtol=0, atol=1e-9 * scale * (1 + 10 * k))


def test_waypoints_ends():
    pts = [[0, 0, 1], [10, 0, 1], [10, 10, 3]]
    w = Waypoints(points=pts, speed=2.0)
    T = w.duration
    assert T == pytest.approx((10.0 + math.sqrt(104.0)) / 2.0, rel=1e-15)  # chord lengths / speed
    pe, ve, ae = w.evaluate(T)
    p, v, a = w.evaluate(T + 7.0)
    np.testing.assert_allclose(p, pe + 7.0 * ve, rtol=1e-13)
    np.testing.assert_allclose(v, ve, rtol=1e-15)
    assert not a.any()
    p, v, a = Waypoints(points=pts, speed=2.0, end="hold").evaluate(np.array([T, T + 7.0]))
    np.testing.assert_allclose(p, [pts[-1]] * 2, atol=1e-12)
    assert not v[1].any() and not a[1].any()
    p, v, a = w.evaluate(-3.0)
    assert np.array_equal(p, pts[0]) and not v.any() and not a.any()


def test_two_waypoints_give_a_straight_line():
    w = Waypoints(points=[[0, 0, 0], [3, 4, 0]], speed=0.5)
    p, v, a = w.evaluate(np.array([0.0, 5.0, 10.0, 12.0]))
    np.testing.assert_allclose(p, [[0, 0, 0], [1.5, 2, 0], [3, 4, 0], [3.6, 4.8, 0]], atol=1e-14)
    np.testing.assert_allclose(v, [[0.3, 0.4, 0]] * 4, atol=1e-15)
    np.testing.assert_allclose(a, 0.0, atol=1e-15)


# --- all kinds: ends, packing, specs, validation -----------------------------------------------

EXAMPLES = [
    Helix(),
    Helix(radius=2.0, omega=-0.3, climb=0.05, center=(1.0, 2.0, 3.0), phase=1.0),
    Circle(radius=5.0, omega=0.2, depth=10.0, center=(1.0, -1.0), phase=0.3),
    Line(start=(1.0, 2.0, 3.0), velocity=(0.5, -0.2, 0.1)),
    Lawnmower(),
    Lawnmower(legs=3, end="hold", first_turn="left", heading=2.0),
    Waypoints(points=[[0, 0, 0], [10, 2, 1], [15, 12, 3], [5, 20, 3], [0, 10, 2]], speed=1.2),
    Waypoints(points=[[0, 0, 0], [4, 3, 0]], speed=0.5, end="hold"),
]


@pytest.mark.parametrize("ref", EXAMPLES, ids=lambda r: r.kind)
def test_finite_everywhere_including_before_start_and_after_end(ref):
    d = ref.duration if math.isfinite(ref.duration) else 600.0
    ts = np.array([-1e300, -1e12, -1.0, -1e-300, 0.0, 0.5 * d, d, np.nextafter(d, np.inf),
                   d + 1.0, 1e6, 1e12, 1e300, *np.linspace(-10, 2 * d, 1001)])
    for arr in ref.evaluate(ts):
        assert np.all(np.isfinite(arr))


@settings(max_examples=60)
@given(st.sampled_from(EXAMPLES), st.floats(-1e300, 1e300))
def test_finite_at_any_finite_time(ref, t):
    for arr in ref.evaluate(t):
        assert np.all(np.isfinite(arr))


@pytest.mark.parametrize("ref", EXAMPLES, ids=lambda r: r.kind)
def test_pack_is_self_describing_and_matches_evaluate(ref):
    rp = ref.pack()
    assert rp.dtype == np.float64 and rp.ndim == 1 and rp.flags.c_contiguous
    m = int(rp[2])
    assert rp[0] == 1 and rp[1] == rp.size == HEADER + m * (1 + SEG) and rp[3] == SEG
    ts = np.linspace(-5.0, 1.3 * (ref.duration if math.isfinite(ref.duration) else 300.0), 97)
    p, v, a = ref.evaluate(ts)
    for j, t in enumerate(ts):
        assert np.array_equal(_pack_eval(rp, t), np.stack([p[j], v[j], a[j]]))
    rp[:] = 0.0  # pack() hands out a copy
    assert np.array_equal(ref.pack()[:4], [1, ref.pack().size, m, SEG])


def test_malformed_pack_gives_nan_without_reading_out_of_bounds():
    rp = Waypoints(points=[[0, 0, 0], [1, 0, 0], [1, 1, 0]]).pack()
    for bad in (rp[:-1], rp[:3], np.concatenate([[2.0], rp[1:]]), np.concatenate([rp[:2], [1e18], rp[3:]]),
                np.concatenate([rp[:2], [np.nan], rp[3:]]), np.zeros(0)):
        assert np.all(np.isnan(_pack_eval(np.ascontiguousarray(bad), 1.0)))


@pytest.mark.parametrize("ref", EXAMPLES, ids=lambda r: r.kind)
def test_describe_round_trips_through_json_and_build_reference(ref):
    spec = json.loads(json.dumps(ref.describe()))
    assert spec["kind"] == ref.kind and REFERENCES[spec["kind"]] is type(ref)
    again = build_reference(spec)
    assert again == ref
    assert np.array_equal(again.pack(), ref.pack())


def test_registry_and_build_errors():
    assert set(REFERENCES) == {"helix", "circle", "line", "lawnmower", "waypoints"}
    assert build_reference({"kind": "helix"}) == Helix()
    with pytest.raises(ValueError, match="kind"):
        build_reference({"kind": "spiral"})
    with pytest.raises(ValueError, match="radiuss"):
        build_reference({"kind": "helix", "radiuss": 3.0})
    with pytest.raises(ValueError, match="depth"):
        build_reference({"kind": "circle", "radius": 3.0, "omega": 0.1})


@pytest.mark.parametrize("cls, kwargs, field", [
    (Helix, {"radius": 0.0}, "radius"),
    (Helix, {"radius": -1.0}, "radius"),
    (Helix, {"omega": math.inf}, "omega"),
    (Helix, {"climb": math.nan}, "climb"),
    (Helix, {"center": (0.0, 1.0)}, "center"),
    (Helix, {"phase": "0"}, "phase"),
    (Circle, {"radius": 1.0, "omega": 0.1, "depth": True}, "depth"),
    (Line, {"velocity": (1.0, 0.0, 1e9)}, "velocity"),
    (Lawnmower, {"legs": 0}, "legs"),
    (Lawnmower, {"legs": 2.5}, "legs"),
    (Lawnmower, {"spacing": 0.0}, "spacing"),
    (Lawnmower, {"speed": -1.0}, "speed"),
    (Lawnmower, {"first_turn": "up"}, "first_turn"),
    (Lawnmower, {"end": "loop"}, "end"),
    (Waypoints, {"points": [[0, 0, 0]]}, "points"),
    (Waypoints, {"points": [[0, 0, 0], [0, 0, 0]]}, "points"),
    (Waypoints, {"points": [[0, 0], [1, 1]]}, "points"),
    (Waypoints, {"points": [[0, 0, 0], [1, 0, 0]], "speed": 0.0}, "speed"),
])
def test_validation_names_the_field_and_range(cls, kwargs, field):
    base = {"points": [[0, 0, 0], [1, 0, 0]]} if cls is Waypoints else {}
    base.update({"radius": 1.0, "omega": 0.1, "depth": 1.0} if cls is Circle else {})
    base.update({"velocity": (1.0, 0.0, 0.0)} if cls is Line else {})
    with pytest.raises(ValueError) as exc:
        cls(**{**base, **kwargs})
    msg = str(exc.value)
    assert f".{field}" in msg and "\n" not in msg
