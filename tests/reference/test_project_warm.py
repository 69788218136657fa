"""The projection's two savings give the same bits as the plain search.

* :func:`project_from` given the path point at the guess returns exactly what :func:`project`
  returns (which evaluates that point itself): the path-following metrics pass the previous
  step's point instead of evaluating it again;
* the search ends a halving loop once the step is below half an ulp of s (every further trial is
  s itself, never accepted): compared, bit for bit, with the same search without that shortcut,
  made from :func:`project_from`'s own source with the shortcut's two lines removed.

Both are checked on sequences of positions that follow a path closely (2 or 3 steps per
projection), and that sit near a helix's axis, where the distance is flat in s to rounding and
the search ends in a failed halving loop (the transient of the paper's Section 4 run).
"""
from __future__ import annotations

import inspect
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from auvtrack.reference import Circle, Helix, Lawnmower
from auvtrack.reference import path as path_module
from auvtrack.reference.kernel import reference_point
from auvtrack.reference.path import project, project_from

REFS = {
    "helix": Helix(radius=4.0, omega=0.1, climb=0.05, center=(0.0, 0.0, 0.0)),
    "circle": Circle(radius=40.0, omega=-0.025, depth=10.0, center=(3.0, -4.0), phase=0.7),
    "lawnmower": Lawnmower(leg_length=20.0, spacing=60.0, legs=3, speed=1.25, depth=5.0, heading=0.4),
}
WINDOW = 10.0
SHORTCUT = "            if s + step == s:"


def _without_shortcut():
    """``project_from`` (Python) without the half-ulp shortcut, from its own source."""
    lines = inspect.getsource(project_from.py_func).splitlines()
    i = next(k for k, line in enumerate(lines) if line.startswith(SHORTCUT))
    assert lines[i + 1].strip() == "break"
    body = "\n".join(line for k, line in enumerate(lines) if k not in (i, i + 1) and not line.startswith("@"))
    scope = dict(vars(path_module))
    exec(compile(body, "<project_from without the shortcut>", "exec"), scope)  # the module's own source
    return scope["project_from"]


PLAIN = _without_shortcut()


def _walk(ref, kind: str, rng: np.random.Generator, n: int) -> list[tuple[float, float, float]]:
    """Positions at successive 1 ms steps: on the path plus a slowly drifting offset, or near the helix axis."""
    t = np.arange(n) * 1e-3 + 0.5
    pos, _, _ = ref.evaluate(t)
    if kind == "axis":  # about the helix's axis, at the path's depth: D(s) flat to rounding
        pos = np.column_stack([np.zeros(n), np.zeros(n), pos[:, 2]])
    offset = np.cumsum(rng.normal(0.0, 1e-3, (n, 3)), axis=0) + rng.normal(0.0, 0.3, 3)
    return [tuple(map(float, p)) for p in pos + offset]


def _sequence(ref_p, points, step):
    """(s, point) of each position, each search started from the previous answer (``step`` one search)."""
    out, s, pt = [], 0.5, reference_point(ref_p, 0.5)
    for p in points:
        s, pt = step(ref_p, s, pt, p)
        out.append((s, pt))
    return out


@pytest.mark.parametrize("case", ["helix", "axis", "circle", "lawnmower"])
@settings(max_examples=4, deadline=None)
@given(seed=st.integers(0, 2**32 - 1))
def test_warm_start_and_shortcut_give_the_plain_search_bit_for_bit(case, seed):
    ref = REFS["helix" if case == "axis" else case]
    ref_p = ref.pack()
    points = _walk(ref, case, np.random.default_rng(seed), 300)
    fresh = _sequence(ref_p, points, lambda r, s, pt, p: project(r, s, p, WINDOW))
    warm = _sequence(ref_p, points, lambda r, s, pt, p: project_from(r, s, pt, p, WINDOW))
    assert warm == fresh  # floats compared with ==: the same bits (no NaN here)
    assert all(math.isfinite(s) for s, _ in fresh)
    plain = _sequence(ref_p, points[:60], lambda r, s, pt, p: PLAIN(r, s, pt, p, WINDOW))
    quick = _sequence(ref_p, points[:60], lambda r, s, pt, p: project_from.py_func(r, s, pt, p, WINDOW))
    assert quick == plain


def test_the_axis_case_reaches_the_shortcut():
    """Near the helix's axis some searches do end in a halving loop that the shortcut cuts short."""
    ref_p = REFS["helix"].pack()
    points = _walk(REFS["helix"], "axis", np.random.default_rng(1), 200)
    calls = {"n": 0}
    scope = dict(vars(path_module))

    def counted(path, s):
        calls["n"] += 1
        return reference_point(path, s)

    scope["reference_point"] = counted
    plain = type(PLAIN)(PLAIN.__code__, {**scope})
    quick = type(PLAIN)(project_from.py_func.__code__, {**scope})
    _sequence(ref_p, points, lambda r, s, pt, p: plain(r, s, pt, p, WINDOW))
    n_plain, calls["n"] = calls["n"], 0
    _sequence(ref_p, points, lambda r, s, pt, p: quick(r, s, pt, p, WINDOW))
    assert calls["n"] < n_plain
