"""The reference as a path: projection on it and the path-frame errors, for every reference kind.

* a point put at known cross-track and vertical offsets from a path point is projected back on
  that point, its errors are the offsets, whatever the reference kind and the guess (hypothesis);
* the projection equals brute-force minimisation of the distance over a fine grid of the window;
* from any guess the answer is a point no farther than the guess, inside the window, where the
  distance is stationary (or at the window's edge, or at the end of a part where the path moves);
* hand-computed cases: a circle's outside is to its left when it turns right, a line's timing error
  is the distance along it, a point behind a lawnmower's start projects on the start.
"""
from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from auvtrack.reference import Circle, Helix, Lawnmower, Line, Waypoints
from auvtrack.reference.path import along_track_error, path_errors, project

REFS = {
    "helix": Helix(radius=30.0, omega=1.25 / 30.0, climb=0.05, center=(-30.0, 0.0, 2.0)),
    "circle": Circle(radius=40.0, omega=-0.025, depth=10.0, center=(3.0, -4.0), phase=0.7),
    "line": Line(start=(1.0, 2.0, 3.0), velocity=(0.8, -0.6, 0.1)),
    "lawnmower": Lawnmower(leg_length=20.0, spacing=60.0, legs=3, speed=1.25, depth=5.0, heading=0.4),
    "waypoints": Waypoints(points=[[0.0, 0.0, 2.0], [60.0, 0.0, 4.0], [110.0, 30.0, 6.0], [110.0, 90.0, 6.0],
                                   [60.0, 120.0, 4.0]], speed=1.25),
}
SPAN = {"helix": (0.0, 300.0), "circle": (0.0, 300.0), "line": (-50.0, 50.0), "lawnmower": (0.5, 182.0),
        "waypoints": (0.5, 250.0)}
WINDOW = 10.0


def _frame(ref, s):
    """Unit tangent, horizontal normal (to the right) and vertical normal (t x n_h, downwards) at s."""
    _, v, _ = ref.evaluate(s)
    tan = v / np.linalg.norm(v)
    nh = np.array([-v[1], v[0], 0.0]) / math.hypot(v[0], v[1])
    return tan, nh, np.cross(tan, nh)


def _curvature_radius(ref, s):
    _, v, a = ref.evaluate(s)
    k = np.linalg.norm(np.cross(v, a)) / np.linalg.norm(v) ** 3
    return math.inf if k == 0 else 1.0 / k


def _brute_force(ref, p, lo, hi, n=200_001):
    ts = np.linspace(lo, hi, n)
    pos, _, _ = ref.evaluate(ts)
    d = np.linalg.norm(pos - p, axis=1)
    i = int(np.argmin(d))
    return ts[i], d[i], ts[1] - ts[0]


@settings(max_examples=60)
@given(kind=st.sampled_from(sorted(REFS)), u=st.floats(0.0, 1.0), a=st.floats(-0.3, 0.3), b=st.floats(-0.3, 0.3),
       shift=st.floats(-2.0, 2.0))
def test_offsets_from_a_path_point_project_back_on_it(kind, u, a, b, shift):
    """p = eta_d(s0) + y n_h + z n_v, |(y, z)| below a third of the curvature radius: s = s0, (y_e, z_e) = (y, z)."""
    ref = REFS[kind]
    lo, hi = SPAN[kind]
    s0 = lo + u * (hi - lo)
    rc = min(_curvature_radius(ref, s0), 20.0)
    y, z = a * rc, b * rc
    _, nh, nv = _frame(ref, s0)
    pos, v, _ = ref.evaluate(s0)
    p = tuple(pos + y * nh + z * nv)
    s, pt = project(ref.pack(), max(s0 + shift, lo), p, WINDOW)  # a guess where the path moves
    speed = float(np.linalg.norm(v))
    assert abs(s - s0) * speed <= 1e-7
    x_e, y_e, z_e = path_errors(pt, p)
    assert abs(y_e - y) <= 1e-7 and abs(z_e - z) <= 1e-7 and abs(x_e) <= 1e-7
    assert along_track_error(pt, s, s0 - 3.0) == pytest.approx(3.0 * speed, rel=1e-6)


@pytest.mark.parametrize("kind", sorted(REFS))
def test_projection_equals_brute_force_over_a_fine_grid(kind):
    ref = REFS[kind]
    lo, hi = SPAN[kind]
    rng = np.random.default_rng(5)
    for _ in range(12):
        s0 = rng.uniform(lo + 2, hi - 2)
        pos, _, _ = ref.evaluate(s0)
        p = pos + rng.normal(0.0, 1.0, 3)
        s, pt = project(ref.pack(), s0, tuple(p), WINDOW)
        s_grid, d_grid, h = _brute_force(ref, p, s0 - 3.0, s0 + 3.0)
        d = float(np.linalg.norm(np.asarray(pt[0]) - p))
        assert d <= d_grid + 1e-12
        assert d == pytest.approx(d_grid, abs=1e-6)
        assert abs(s - s_grid) <= 2 * h


@settings(max_examples=80)
@given(kind=st.sampled_from(sorted(REFS)), u=st.floats(0.0, 1.0), off=st.tuples(*[st.floats(-8.0, 8.0)] * 3),
       shift=st.floats(-6.0, 6.0))
def test_the_answer_is_a_descent_to_a_stationary_point_inside_the_window(kind, u, off, shift):
    ref = REFS[kind]
    lo, hi = SPAN[kind]
    s_guess = lo + u * (hi - lo) + shift
    pos, _, _ = ref.evaluate(lo + u * (hi - lo))
    p = pos + np.asarray(off)
    packed = ref.pack()
    s, pt = project(packed, s_guess, tuple(p), WINDOW)
    assert s_guess - WINDOW <= s <= s_guess + WINDOW
    d = np.asarray(pt[0]) - p
    d_guess = ref.evaluate(s_guess)[0] - p
    assert d @ d <= d_guess @ d_guess
    np.testing.assert_array_equal(pt[0], ref.evaluate(s)[0])
    v = np.asarray(pt[1])
    at_edge = abs(abs(s - s_guess) - WINDOW) < 1e-9
    standing_next = any(not np.any(ref.evaluate(s + h)[1]) for h in (-1e-6, 1e-6))  # the moving part's end
    assume(not at_edge and not standing_next and v @ v > 0)
    radius = _curvature_radius(ref, s)
    assume(np.linalg.norm(d) < 0.5 * radius)  # well inside the curvature: Newton converges
    assert abs(d @ v) <= 1e-7 * max(1.0, np.linalg.norm(d)) * np.linalg.norm(v)


def test_outside_of_a_right_turning_circle_is_to_its_left():
    """NED, omega > 0 turns from north to east (right): the centre is to the right, the outside to the left."""
    c = Circle(radius=10.0, omega=0.1, depth=3.0)
    pos, _, _ = c.evaluate(5.0)
    p = tuple(pos + np.array([0.2 * pos[0], 0.2 * pos[1], 0.5]))  # 2 m outside (centre 0), 0.5 m deeper
    s, pt = project(c.pack(), 4.0, p, WINDOW)
    assert s == pytest.approx(5.0, abs=1e-9)
    x_e, y_e, z_e = path_errors(pt, p)
    assert (y_e, z_e) == (pytest.approx(-2.0, abs=1e-12), pytest.approx(0.5, abs=1e-12))


def test_a_climbing_line_frame_by_hand():
    """A line north climbing at 45 deg: a point 1 m straight below it has z_e = cos 45 deg, x_e = -sin 45 deg
    relative to the same path point, and projects to the point sqrt(1/2) m further back along the line."""
    line = Line(start=(0.0, 0.0, 10.0), velocity=(1.0, 0.0, -1.0))
    pos, _, _ = line.evaluate(2.0)
    p = tuple(pos + np.array([0.0, 0.0, 1.0]))
    _, pt2 = project(line.pack(), 2.0, p, 1e-12)  # window ~0: stays at s = 2
    x_e, y_e, z_e = path_errors(pt2, p)
    h = math.sqrt(0.5)
    assert (x_e, y_e, z_e) == (pytest.approx(-h, abs=1e-15), 0.0, pytest.approx(h, abs=1e-15))
    s, pt = project(line.pack(), 2.0, p, WINDOW)
    assert s == pytest.approx(1.5, abs=1e-12)
    assert path_errors(pt, p) == (pytest.approx(0.0, abs=1e-12), 0.0, pytest.approx(h, abs=1e-12))
    assert along_track_error(pt, s, 2.0) == pytest.approx(-0.5 * math.sqrt(2.0), abs=1e-12)


def test_behind_the_start_of_a_lawnmower_projects_on_its_start():
    """Before t = 0 the lawnmower holds its start: the moving path is not left for a standing part that is
    no closer, so a point 1 m behind the start projects on t = 0, 1 m behind along the track."""
    m = Lawnmower(leg_length=20.0, spacing=60.0, legs=2, speed=1.25, depth=5.0)
    s, pt = project(m.pack(), 0.0, (-1.0, 0.3, 5.2), WINDOW)
    assert s == 0.0
    assert path_errors(pt, (-1.0, 0.3, 5.2)) == (pytest.approx(-1.0), pytest.approx(0.3), pytest.approx(0.2))


def test_beyond_a_held_end_projects_on_the_end_of_the_leg():
    """After a ``hold`` end the path stands still: from a guess on the leg the search stops at the leg's end
    (the last moving instant, 20 s), whose frame is the leg's; from a guess in the standing part it stays
    there, and the errors are then the horizontal distance and the depth difference."""
    m = Lawnmower(leg_length=20.0, spacing=60.0, legs=1, speed=1.0, depth=5.0, end="hold")
    p = (23.0, 4.0, 6.0)
    s, pt = project(m.pack(), 18.0, p, WINDOW)
    assert 20.0 - 1e-7 < s < 20.0 and pt[1] == (1.0, 0.0, 0.0)
    assert path_errors(pt, p) == (pytest.approx(3.0, abs=1e-7), pytest.approx(4.0), pytest.approx(1.0))
    s, pt = project(m.pack(), 30.0, p, WINDOW)
    assert s == 30.0 and pt[1] == (0.0, 0.0, 0.0)
    assert path_errors(pt, p) == (0.0, 5.0, pytest.approx(1.0))
    assert along_track_error(pt, s, 10.0) == 0.0


def test_a_vehicle_moving_back_behind_the_start_and_forward_again_keeps_to_the_moving_path():
    """Warm-started step by step, the projection follows a point that goes 2 m behind a lawnmower's start
    and back onto the first leg: it stays on the moving path, at the start while the point is behind it."""
    m = Lawnmower(leg_length=20.0, spacing=60.0, legs=2, speed=1.25, depth=5.0)
    xs = np.concatenate([np.linspace(1.0, -2.0, 300), np.linspace(-2.0, 3.0, 500)])
    s = 0.8
    for x in xs:
        s, pt = project(m.pack(), s, (x, 0.1, 5.0), WINDOW)
        assert s >= 0.0
        assert s == pytest.approx(max(x, 0.0) / 1.25, abs=1e-6)
