"""The generated numbers of docs/vehicles.md, section "Feasibility", computed by the feasibility code.

``python -m tools.feasibility_doc render`` rewrites the block between
``<!-- BEGIN GENERATED feasibility ... -->`` and ``<!-- END GENERATED feasibility -->``;
``... doc check`` exits with status 1 when the block differs from what the code gives
(``tests/feasibility/test_feasibility.py`` runs the same comparison).  Importing this module runs nothing.
"""
from __future__ import annotations

import re
import sys
from pathlib import Path

import numpy as np

DOC = Path(__file__).resolve().parents[1] / "docs" / "vehicles.md"
NAME = "feasibility"
BLOCK_RE = re.compile(rf"(<!-- BEGIN GENERATED {NAME}[^>]*-->\n)(.*?)(<!-- END GENERATED {NAME} -->)", re.S)
TRIM_SPEEDS = (0.5, 0.75, 1.0, 1.1, 1.25, 1.5, 2.0)   # m/s
TURN_SPEEDS = (0.8, 1.0, 1.25, 1.5)                    # m/s
CURRENT_CASE = (30.0, 1.0, 0.2)                        # ground radius (m), speed (m/s), current (m/s)


def _fmt(x: float, digits: int = 3) -> str:
    return f"{x:.{digits}g}"


def prestero_trim_rows() -> list[str]:
    """Table rows: Prestero's level trim at :data:`TRIM_SPEEDS` against its preset's limits."""
    from auvtrack.feasibility.assess import status_of
    from auvtrack.feasibility.steady6 import Steady6
    m = Steady6("remus100_prestero")
    rows = []
    for u in TRIM_SPEEDS:
        s = m.solve(u, 0.0, 0.0)
        name, use = s.worst
        rows.append(f"| {u:g} | {_fmt(s.inputs['delta_s'])} | {_fmt(s.inputs['rpm'], 4)} | "
                    f"{_fmt(s.inputs['pitch'])} | {_fmt(s.inputs['roll'])} | "
                    f"{status_of(use)} ({m.limits[name].label}, {use:.0%}) |")
    return rows


SCAN = (0.4, 2.0, 0.01)   # m/s: the speeds at which Prestero's level trim is scanned


def prestero_fin_gaps() -> tuple[list[tuple[float, float]], float]:
    """Speed intervals (m/s) where Prestero's level trim exceeds the stern-plane limit, and that limit (deg).

    Scanned on the :data:`SCAN` grid, each trim starting from the next faster one.
    """
    from auvtrack.feasibility.steady6 import Steady6
    m = Steady6("remus100_prestero")
    lim = m.limits["delta_s"].available
    lo, hi, step = SCAN
    speeds = np.round(np.arange(hi, lo - 1e-9, -step), 2)  # down from cruise, each trim from the previous one
    z, over = None, {}
    for u in speeds:
        s = m.solve(float(u), 0.0, 0.0, z)
        z = s.z
        over[float(u)] = abs(s.inputs["delta_s"]) > lim
    gaps, start = [], None
    grid = sorted(over)
    for i, u in enumerate(grid):
        if over[u] and start is None:
            start = u
        if start is not None and (not over[u] or i == len(grid) - 1):
            gaps.append((start, u if over[u] else grid[i - 1]))
            start = None
    return gaps, lim


def fossen_turn_rows() -> list[str]:
    """Table rows: Fossen's tightest steady turn at :data:`TURN_SPEEDS` (level, speed held)."""
    from auvtrack.feasibility.steady import tightest_turn
    from auvtrack.feasibility.steady6 import Steady6
    m = Steady6("remus100_fossen")
    rows = []
    for u in TURN_SPEEDS:
        sb, pt = tightest_turn(m, u, 0.0, 1.0), tightest_turn(m, u, 0.0, -1.0)
        rows.append(f"| {u:g} | {_fmt(sb.radius, 4)} | {_fmt(pt.radius, 4)} | {m.limits[sb.limit].label} | "
                    f"{_fmt(sb.state.inputs['rpm'], 4)} |")
    return rows


def fossen_classic_diameter(speed: float = 1.0) -> tuple[float, float]:
    """Steady diameter (m) and speed (m/s) of Fossen's classic turning circle at ``speed``.

    Full rudder, stern plane 0 and the propeller speed of straight flight at ``speed``.

    Simulated with the truth's reference integrator (600 s, dt 0.02 s) and measured as
    :func:`auvtrack.studies.manoeuvres.turning_circle_metrics` does.
    """
    from auvtrack.studies.manoeuvres import turning_circle_metrics
    from auvtrack.plant.sixdof.layout import NX6, P_DMAX
    from auvtrack.plant.sixdof.truth import integrate_open_loop, pack_truth, trim_rpm
    pp = pack_truth("remus100_fossen")
    n = trim_rpm("remus100_fossen", pp, speed)
    x0 = np.zeros(NX6)
    x0[6], x0[14] = speed, n
    times = tuple(np.round(np.arange(0.5, 600.0 + 1e-9, 0.5), 9))
    res = integrate_open_loop("remus100_fossen", (pp[P_DMAX], 0.0, n), 600.0, 0.02, x0=x0, times=times, pp=pp)
    X = np.array([res[t] for t in times])
    tc = turning_circle_metrics(np.array(times), X[:, 0], X[:, 1], X[:, 5], X[:, 6], X[:, 7], X[:, 11], t0=300.0)
    return tc["steady_diameter"], float(np.linalg.norm(X[-1, 6:9]))


def current_case() -> tuple[float, float, float, str]:
    """The ground circle of :data:`CURRENT_CASE` through the water.

    Returns (demanded water radius (m), tightest radius (m), water speed (m/s), verdict).
    """
    from auvtrack.feasibility.assess import assess
    r, u, v = CURRENT_CASE
    f = assess({"reference": {"kind": "circle", "radius": r, "omega": u / r, "depth": 10.0},
                "plant": {"model": "6dof", "preset": "remus100_fossen"},
                "disturbance": [{"kind": "current", "mean": [v, 0.0, 0.0], "sigma": [0.0, 0.0, 0.0]}]})
    (turn,) = [c for c in f.checks if c.name == "turn to starboard"]
    return turn.required, turn.available, u - v, f.verdict


def block() -> str:
    """The generated Markdown (no trailing newline)."""
    gaps, lim = prestero_fin_gaps()
    where = " and ".join(f"{a:g} to {b:g} m/s" for a, b in gaps)
    d, u = fossen_classic_diameter()
    req, avail, uw, verdict = current_case()
    r, ug, v = CURRENT_CASE
    lines = ["`remus100_prestero`, level straight flight (trim of the truth, preset limits):", "",
             "| speed (m/s) | stern plane (deg) | propeller (rpm) | pitch (deg) | roll (deg) "
             "| status (most used limit) |",
             "|---|---|---|---|---|---|", *prestero_trim_rows(), "",
             f"The level trim needs more stern plane than the {_fmt(lim)} deg limit from {where} (scanned from "
             f"{SCAN[0]:g} to {SCAN[1]:g} m/s every {SCAN[2]:g} m/s). As the speed falls the trim flies nose down at "
             "a growing angle of attack (the pitch column), beyond the small-angle range of P01's coefficients.", "",
             "`remus100_fossen`, tightest steady level turn (speed held by the propeller):", "",
             "| speed (m/s) | radius to starboard (m) | radius to port (m) | binding limit | propeller (rpm) |",
             "|---|---|---|---|---|", *fossen_turn_rows(), "",
             f"The classic turning circle at 1 m/s (full rudder, stern plane 0, the straight-flight rpm, speed "
             f"falling to {_fmt(u)} m/s) has a steady diameter of {_fmt(d)} m.  A {r:g} m ground circle at "
             f"{ug:g} m/s in a {v:g} m/s current asks for a {_fmt(req)} m turn through the water at {_fmt(uw)} m/s "
             f"(following current), where the tightest is {_fmt(avail)} m: {verdict}."]
    return "\n".join(lines)


def render_text(text: str) -> str:
    """``text`` with the generated block replaced by :func:`block`."""
    if not BLOCK_RE.search(text):
        raise KeyError(f"{DOC.name}: no generated block {NAME!r}")
    return BLOCK_RE.sub(lambda m: m.group(1) + block() + "\n" + m.group(3), text)


def main(argv: list[str] | None = None) -> int:
    """``python -m tools.feasibility_doc render | check``; returns the exit status."""
    args = sys.argv[1:] if argv is None else argv
    old = DOC.read_text()
    if args == ["render"]:
        DOC.write_text(render_text(old))
        return 0
    if args == ["check"]:
        if render_text(old) != old:
            print(f"stale generated block in {DOC} (python -m tools.feasibility_doc render)")
            return 1
        return 0
    print("usage: python -m tools.feasibility_doc render | check", file=sys.stderr)
    return 2


if __name__ == "__main__":  # pragma: no cover
    raise SystemExit(main())
