"""Compiled functions exercising every construct of the lane rewrite (auvtrack.engine.lanes), for tests.

Each is an ordinary compiled function of scalars; tests/engine/test_simd.py checks that its lane form gives,
lane by lane, exactly the scalar function's results.
"""
import math

from auvtrack.jit import njit, njit_noalloc
from auvtrack.jit.vecmath import atanh4, exp8, pow4, sincos4


@njit
def helper(x, y):
    """A called function with an early return."""
    if x > y:
        return x - y
    return 0.25 * (y - x)


@njit
def branches(x, y):
    """if / elif / else, nested ifs, an early return, a ternary, and/or/not, chained comparison."""
    if x > y:
        z = x - y
        if z > 1.0:
            return z * 2.0, 1
    elif x < -y:
        z = x + y
    else:
        z = 0.5
    w = z if z > 0.0 else -z
    flag = 1 if (x > 0.0 and y > 0.0) or not x < 2.0 else 0
    if -1.0 < x <= 1.0:
        w += helper(x, y)
    return w + flag, 2


@njit
def loops(x, n):
    """for with lane-dependent bounds, break, continue; while with a compound condition."""
    s = 0.0
    for i in range(n):
        if i > 5 and x < 0.0:
            break
        if i % 3 == 1:
            continue
        s += x * i
    k = 0
    while s > 1.0 and k < 50:
        s = s * 0.5
        k += 1
    return s, k


@njit
def return_in_loop(x, n):
    """A return inside a loop (lanes leave at different iterations)."""
    for i in range(n):
        x = x * 1.5 - 0.3
        if abs(x) > 10.0:
            return x, i
    return x, -1


@njit_noalloc
def stores(a, x):
    """Masked stores and augmented stores into an array, a uniform loop."""
    for i in range(a.shape[0]):
        if x > i:
            a[i] += x
        else:
            a[i] = -a[i]
    return a[0] + a[a.shape[0] - 1]



@njit_noalloc
def gathers(a, b, i, j):
    """Loads and stores at each lane's own index (1-D and 2-D, an index of lanes next to a plain one)."""
    x = a[i] + b[i, j] * 0.5 - b[j, 1]
    a[j] = x - a[i]
    b[i, 2] += x
    return x + a[j] * b[i, 2]

@njit
def maths(x, p):
    """Scalar maths per lane: exp, pow, tanh, min, max, int, floor, isfinite, division."""
    ax = abs(x)
    return (math.exp(-ax) + ax ** p + math.tanh(x), min(x, p), max(x, 2.0 * p), int(x), math.floor(x),
            math.isfinite(x / p), x / (p + 3.0))


@njit
def shared(x, p):
    """Scalar and vector libm calls, in branches (partial masks) and outside: the calls a lane form
    makes once when the lanes' arguments have the same bits."""
    r = 0.0
    if x > 0.25:
        r = math.sin(x) + math.cos(p) + abs(x) ** p
    else:
        r = math.atan2(x, p) + math.exp(x)
    s, c = sincos4((x, p, 0.0, 0.0))
    q = pow4((abs(x), abs(p) + 0.5, 2.0, 1.0), (p, p, p, p))
    z = atanh4((x / (abs(x) + 1.0), 0.5 * math.tanh(p), 0.0, 0.0))
    e = exp8((x, p, -x, -p, 0.0, 0.0, 0.0, 0.0))
    return r, s[0] + c[1], s[1] - c[0], q[0] + q[1], q[2], z[0] + z[1], e[0] + e[1] - e[2] * e[3]


CASES = {"branches": (branches, ("f", "f")), "loops": (loops, ("f", "i")),
         "return_in_loop": (return_in_loop, ("f", "i")), "maths": (maths, ("f", "f")),
         "shared": (shared, ("f", "f"))}
"""name -> (function, argument kinds: "f" float, "i" integer)."""
