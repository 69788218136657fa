"""The generated tables of ``docs/vehicles.md``: the two REMUS 100 truths against the sea trials.

Every number in those tables is computed here, by simulating the truths (the Python RK4 of
:func:`auvtrack.plant.sixdof.truth.integrate_open_loop` over the compiled model) or by the
models' own balance equations; the published numbers are quoted with their sources in
:data:`TRIALS`.  To refresh the document::

    python -m tools.sea_trials render     # rewrite the generated blocks
    python -m tools.sea_trials check      # exit 1 when a block is stale

A block sits between ``<!-- BEGIN GENERATED name ... -->`` and ``<!-- END GENERATED name -->``
(the markers of :mod:`tools.findings`).  Conditions of the trials (Prestero 2001,
ch. 7-8): straight running at 1.54 m/s, the propeller at a constant 1500 rpm, fins stepped.  Each
truth is started there with its propeller trimmed to hold 1.54 m/s (the truths disagree on the
speed a given rpm makes, which the first row shows), so that the fins act at the trial's speed.
The stern-plane steps follow P01's own simulation protocol (§8.4: zero fins for 2 s from straight
running, then the step for 2 s; changes over the step); in the field the vehicle was under depth
control until the step, so the drift rows show how much of a truth's change is its own motion.

This module is not a study (it defines no ``STUDY``); importing it runs nothing.
"""
from __future__ import annotations

import functools
import math
import sys
from pathlib import Path

import numpy as np

from tools.findings import BLOCK_RE
from auvtrack.report import fmt

ROOT = Path(__file__).resolve().parents[1]
DOC = ROOT / "docs" / "vehicles.md"
TRUTHS = ("remus100_prestero", "remus100_fossen")
U_TRIAL = 1.54   # m/s: P01 Table 8.1, "the operating speed of the vehicle at a propeller RPM of 1500"
RPM_TRIAL = 1500.0
DT = 0.005       # s, RK4 step of the trial simulations
P01 = "P01"      # Prestero (2001), MSc thesis, MIT/WHOI

TRIALS = {
    "speed_1500": ("speed at 1500 rpm (m/s)", 1.54, f"{P01} §7.2, Table 8.1: 1.54 m/s (3 kn) at 1500 rpm"),
    "speed_max": ("speed at n_max = 1525 rpm (m/s)", 2.5, "WHOI Oceanus (2003, 'Robo-Sailors'): REMUS speeds up to "
                  "2.5 m/s; F21/PVS: 2.5 m/s at 1525 rpm (after Allen et al. 2000)"),
    "roll_offset": ("roll in straight running at 1500 rpm (deg)", -5.0, f"{P01} §7.5, Table 8.1: -5 deg, from the "
                    "propeller torque"),
    "yaw_rate": ("yaw rate 5 s after a 4 deg rudder step from straight running (deg/s)", 10.0, f"{P01} §7.5.1, Fig. 7-7: about 10 deg/s "
                 "(depth held by the autopilot)"),
    "up_dz": ("stern planes -2 deg for 2 s (after 2 s at 0): depth change (m)", -0.5, f"{P01} §7.5.2, Fig. 7-8: rises about 0.5 m"),
    "up_dtheta": ("stern planes -2 deg for 2 s (after 2 s at 0): pitch change (deg)", 20.0, f"{P01} §7.5.2, Fig. 7-8: about 20 deg "
                  "nose up (P01's own simulation, §8.4.1, used -4 deg)"),
    "down_dz": ("stern planes +8 deg for 2 s (after 2 s at 0): depth change (m)", 0.4, f"{P01} §7.5.2, Fig. 7-9: dives about 0.4 m "
                "(P01's simulation: 0.6 m)"),
    "down_dtheta": ("stern planes +8 deg for 2 s (after 2 s at 0): pitch change (deg)", -18.0, f"{P01} §7.5.2, Fig. 7-9: about 18 deg "
                    "nose down (P01's simulation: 30 deg)"),
}
"""Trial key -> (quantity, published value, source).  Signs: z down, theta nose up positive."""


def _model(name: str):
    from auvtrack.plant.sixdof.truth import model_of, pack_truth
    return model_of(name), pack_truth(name)


def surge_force(name: str, u: float, rpm: float) -> float:
    """Surge component of M nu_dot (N) in straight, level running at u (m/s), fins at 0, propeller at rpm."""
    from auvtrack.vehicle.kinematics import attitude
    from auvtrack.plant.sixdof.truth import initial_state

    model, pp = _model(name)
    x = initial_state(nu6=(u, 0.0, 0.0, 0.0, 0.0, 0.0), actuators=(0.0, 0.0, rpm))
    cmd = np.zeros(6)
    cmd[2] = rpm
    dx = np.zeros(15)
    model.derivative(x, attitude(0.0, 0.0), (0.0, 0.0, 0.0), (0.0,) * 6, cmd, pp, dx)
    M = np.linalg.inv(pp[0:36].reshape(6, 6))
    return float(M[0] @ dx[6:12])


def speed_at_rpm(name: str, rpm: float) -> float:
    """Steady straight-running speed (m/s) at a propeller speed: the root of :func:`surge_force` in u (bisection)."""
    lo, hi = 0.0, 6.0
    for _ in range(80):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if surge_force(name, mid, rpm) > 0.0 else (lo, mid)
    return 0.5 * (lo + hi)


def roll_offset(name: str, u: float, rpm: float) -> float:
    """Static roll angle (deg) where the propeller's roll torque meets the righting moment (W z_g - B z_b) sin phi."""
    from auvtrack.plant.sixdof.layout import P_B, P_RB, P_RG, P_W
    from auvtrack.plant.sixdof.prestero import propeller as prestero_propeller

    model, pp = _model(name)
    if name == "remus100_prestero":
        K = prestero_propeller(rpm, pp)[1]
    else:
        from auvtrack.plant.sixdof.fossen import FZ_ROLL, propeller
        K = propeller(rpm, u, pp)[1] * pp[FZ_ROLL]
    gm = pp[P_W] * pp[P_RG + 2] - pp[P_B] * pp[P_RB + 2]
    return math.degrees(math.asin(K / gm))


def fin_step(name: str, rudder_deg: float, stern_deg: float, t_pre: float, t_step: float) -> dict:
    """Open-loop fin step from straight, level running at :data:`U_TRIAL` (propeller trimmed).

    The fins are held at zero for ``t_pre`` seconds, then at the given angles for ``t_step``
    seconds (Prestero 2001 §8.4's protocol for the stern-plane steps).

    Parameters
    ----------
    name : str
        Truth.
    rudder_deg, stern_deg : float
        Fin commands (deg), each truth's sign convention (stern planes: + is nose down in both).
    t_pre, t_step : float
        Durations (s).

    Returns
    -------
    dict
        Changes over the step interval: ``dz`` (m, + down), ``dtheta`` (deg, + nose up); at its
        end: ``r`` (deg/s), ``u`` (m/s).
    """
    from auvtrack.plant.sixdof.truth import initial_state, integrate_open_loop, trim_rpm

    _, pp = _model(name)
    rpm = trim_rpm(name, pp, U_TRIAL)
    x = initial_state(nu6=(U_TRIAL, 0.0, 0.0, 0.0, 0.0, 0.0), actuators=(0.0, 0.0, rpm))
    if t_pre > 0.0:
        x = integrate_open_loop(name, (0.0, 0.0, rpm), t_pre, DT, x0=x, pp=pp)["final"]
    y = integrate_open_loop(name, (math.radians(rudder_deg), math.radians(stern_deg), rpm), t_step, DT,
                            x0=x, pp=pp)["final"]
    return {"dz": float(y[2] - x[2]), "dtheta": math.degrees(y[4] - x[4]), "r": math.degrees(y[11]),
            "u": float(y[6])}


@functools.lru_cache(maxsize=None)
def trial_values(name: str) -> dict:
    """Every quantity of :data:`TRIALS` for the truth ``name`` (cached per process), and the drift rows."""
    up = fin_step(name, 0.0, -2.0, 2.0, 2.0)
    down = fin_step(name, 0.0, 8.0, 2.0, 2.0)
    drift = fin_step(name, 0.0, 0.0, 2.0, 2.0)
    turn = fin_step(name, 4.0, 0.0, 0.0, 5.0)
    return {"speed_1500": speed_at_rpm(name, RPM_TRIAL), "speed_max": speed_at_rpm(name, 1525.0),
            "roll_offset": roll_offset(name, U_TRIAL, RPM_TRIAL), "yaw_rate": abs(turn["r"]),
            "up_dz": up["dz"], "up_dtheta": up["dtheta"], "down_dz": down["dz"], "down_dtheta": down["dtheta"],
            "drift_dz": drift["dz"], "drift_dtheta": drift["dtheta"]}


def _clean(x: float, tiny: float = 1e-6) -> float:
    """``x`` with finite-difference and round-off noise below ``tiny`` shown as 0."""
    return 0.0 if abs(x) < tiny else x


def _ratio(model: float, trial: float) -> str:
    return fmt(model / trial, 2) + "×" if trial else "–"


def block_sea_trials() -> str:
    """Markdown table: each published trial number against both truths (value and ratio to the trial)."""
    vals = {n: trial_values(n) for n in TRUTHS}
    head = ("| quantity | REMUS 100 trial | `remus100_prestero` | `remus100_fossen` | source |\n"
            "|---|---|---|---|---|")
    rows = []
    for key, (what, pub, src) in TRIALS.items():
        cells = [f"{fmt(vals[n][key], 3)} ({_ratio(vals[n][key], pub)})" for n in TRUTHS]
        rows.append(f"| {what} | {fmt(pub, 3)} | {cells[0]} | {cells[1]} | {src} |")
    for key, what in (("drift_dz", "no fin step (drift over the same 2 s): depth change (m)"),
                      ("drift_dtheta", "no fin step: pitch change (deg)")):
        rows.append(f"| {what} | – | {fmt(_clean(vals[TRUTHS[0]][key]), 3)} | {fmt(_clean(vals[TRUTHS[1]][key]), 3)} | "
                    "the truths' own motion in the stern-plane rows' interval |")
    return head + "\n" + "\n".join(rows)


def constants() -> dict:
    """The two truths' control and vehicle constants that the trials depend on, in one unit each."""
    from auvtrack.plant.sixdof.fossen import FZ_KR, FZ_KS, FZ_XR, FZ_XS
    from auvtrack.plant.sixdof.layout import P_DMAX, P_NMAX, P_W
    from auvtrack.plant.sixdof.prestero import F_MDS, F_NDR

    out = {}
    for name in TRUTHS:
        _, pp = _model(name)
        if name == "remus100_prestero":
            n_dr, m_ds = abs(pp[F_NDR]), abs(pp[F_MDS])
        else:
            n_dr, m_ds = abs(pp[FZ_XR] * pp[FZ_KR]), abs(pp[FZ_XS] * pp[FZ_KS])
        out[name] = {"rudder": n_dr, "stern": m_ds, "delta_max": math.degrees(pp[P_DMAX]), "n_max": pp[P_NMAX],
                     "mass": pp[P_W] / 9.81}
    return out


def block_constants() -> str:
    """Markdown table of :func:`constants` with the ratio Fossen / Prestero."""
    c = constants()
    rows = [("rudder yaw moment per u² δ_r (N m per (m/s)² rad)", "rudder"),
            ("stern-plane pitch moment per u² δ_s (N m per (m/s)² rad)", "stern"),
            ("fin limit (deg)", "delta_max"), ("propeller limit (rpm)", "n_max"), ("mass (kg)", "mass")]
    head = "| constant | `remus100_prestero` | `remus100_fossen` | Fossen / Prestero |\n|---|---|---|---|"
    body = [f"| {what} | {fmt(c[TRUTHS[0]][k], 4)} | {fmt(c[TRUTHS[1]][k], 4)} | "
            f"{fmt(c[TRUTHS[1]][k] / c[TRUTHS[0]][k], 3)} |" for what, k in rows]
    return head + "\n" + "\n".join(body)


def reduction_comparison(name: str = "remus100_fossen", u0: float = 1.5) -> dict:
    """The reduced 5-DOF model of a Fossen-type truth against the truth's linearisation at u0.

    Returns
    -------
    dict
        ``entries``: (label, truth, 5-DOF) generalized-force slopes; ``eig_truth``,
        ``eig_design``: largest real part of the eigenvalues (1/s); ``surge_err``: largest
        difference of the surge-speed responses to a 1 % thrust step over 30 s, relative to the
        truth's largest response; ``t_q``, ``t_r``: time (s) until the pitch-rate (yaw-rate)
        responses to a 0.01 N m step first differ by more than 10 % of the truth's.
    """
    from auvtrack.vehicle.presets import get_preset, pack_vehicle
    from auvtrack.plant.sixdof.linearise import design_jacobian, step_response, truth_jacobian

    tj = truth_jacobian(name, u0)
    pre = get_preset(name, u0=u0)
    vp = pack_vehicle(pre.m, pre.d, pre.wgml, pre.l)
    dj = design_jacobian(vp, u0)
    K, m = tj["K"], pre.m
    K5 = np.diag(m) @ dj["A"][:5, :5]
    Mt = tj["M"] @ tj["A"][:6, 7]
    entries = [("surge ∂X/∂u (N s/m)", K[0, 0], K5[0, 0]), ("sway ∂Y/∂v", K[1, 1], K5[1, 1]),
               ("heave ∂Z/∂w", K[2, 2], K5[2, 2]), ("pitch ∂M/∂q (N m s)", K[4, 4], K5[3, 3]),
               ("yaw ∂N/∂r", K[5, 5], K5[4, 4]), ("pitch ∂M/∂θ (N m)", Mt[4], m[3] * dj["A"][3, 5]),
               ("sway ∂Y/∂r (N s)", K[1, 5], K5[1, 4]), ("heave ∂Z/∂q", K[2, 4], K5[2, 3]),
               ("pitch ∂M/∂w, Munk (N s)", K[4, 2], K5[3, 2]), ("yaw ∂N/∂v, Munk", K[5, 1], K5[4, 1])]
    idx = [0, 1, 2, 4, 5, 7]
    ts = np.linspace(0.0, 30.0, 3001)
    yt = step_response(tj["A"], tj["B"], 0, 0.01 * tj["tau_u0"], ts)[:, 0]
    y5 = step_response(dj["A"], dj["B"], 0, 0.01 * tj["tau_u0"], ts)[:, 0]
    ts2 = np.linspace(0.0, 3.0, 301)

    def split(col, ch_t, ch_5):
        a = step_response(tj["A"], tj["B"], col, 0.01, ts2)[:, ch_t]
        b = step_response(dj["A"], dj["B"], col, 0.01, ts2)[:, ch_5]
        bad = np.nonzero(np.abs(b - a) > 0.1 * np.abs(a).max())[0]
        return float(ts2[bad[0]]) if bad.size else math.inf
    return {"entries": entries, "eig_truth": float(np.linalg.eigvals(tj["A"]).real.max()),
            "eig_design": float(np.linalg.eigvals(dj["A"]).real.max()),
            "surge_err": float(np.abs(y5 - yt).max() / np.abs(yt).max()),
            "t_q": split(1, 4, 3), "t_r": split(2, 5, 4), "u0": u0, "idx": idx}


def block_reduction() -> str:
    """Markdown: the reduced Fossen REMUS 100 against its truth's linearisation (:func:`reduction_comparison`)."""
    r = reduction_comparison()
    head = (f"At U₀ = {fmt(r['u0'], 3)} m/s (`remus100_fossen`; `tests/vehicle/test_vehicle_file.py`):\n\n"
            "| generalized-force slope | truth (finite differences) | 5-DOF design model |\n|---|---|---|")
    body = [f"| {what} | {fmt(_clean(a, 1e-9), 4)} | {fmt(_clean(b, 1e-9), 4)} |" for what, a, b in r["entries"]]
    tail = (f"\n\nLargest real part of the eigenvalues: truth {fmt(r['eig_truth'], 3)} 1/s, 5-DOF model "
            f"{fmt(r['eig_design'], 3)} 1/s. Surge response to a 1 % thrust step: the two agree to "
            f"{fmt(100 * r['surge_err'], 2)} % of the response over 30 s. Pitch- and yaw-rate responses to a "
            f"0.01 N m step part by more than 10 % after {fmt(r['t_q'], 2)} s and {fmt(r['t_r'], 2)} s.")
    return head + "\n" + "\n".join(body) + tail


def remus600_values() -> dict:
    """The shipped ``remus600`` flown open loop and reduced: speeds, a turning circle, the 5-DOF numbers."""
    from auvtrack.vehicle.presets import get_preset
    from auvtrack.plant.sixdof.truth import initial_state, integrate_open_loop, pack_truth, trim_rpm
    from auvtrack.plant.sixdof.layout import P_NMAX
    from auvtrack.studies.manoeuvres import turning_circle_metrics

    name = "remus600"
    pp = pack_truth(name)
    n_max = float(pp[P_NMAX])
    u_max = speed_at_rpm(name, n_max)
    rpm = trim_rpm(name, pp, 1.54)
    x0 = initial_state(nu6=(1.54, 0.0, 0.0, 0.0, 0.0, 0.0), actuators=(0.0, 0.0, rpm))
    dt, T = 0.01, 400.0
    times = [round(k * 0.5, 6) for k in range(1, int(T / 0.5) + 1)]
    out = integrate_open_loop(name, (math.radians(15.0), 0.0, rpm), T, dt, x0=x0, pp=pp, times=times)
    X = np.array([out[t] for t in times])
    t = np.array(times)
    tc = turning_circle_metrics(t, X[:, 0], X[:, 1], X[:, 5], X[:, 6], X[:, 7], X[:, 11], 0.0)
    pre = get_preset(name, u0=1.54)
    return {"n_max": n_max, "u_max": u_max, "rpm_cruise": rpm, "tactical": tc["tactical_diameter"],
            "steady": tc["steady_diameter"], "m": pre.m, "d": pre.d, "wgml": pre.wgml, "l": pre.l,
            "dz_turn": float(X[-1, 2]), "u_turn": float(X[-1, 6])}


def block_remus600() -> str:
    """Markdown: the remus600 numbers of :func:`remus600_values`."""
    v = remus600_values()
    return ("| quantity | `remus600` | published |\n|---|---|---|\n"
            f"| speed at n_max = {fmt(v['n_max'], 4)} rpm (m/s) | {fmt(v['u_max'], 3)} | up to 5 kn = 2.57 m/s (R600) |\n"
            f"| propeller speed for 3 kn = 1.54 m/s (rpm) | {fmt(v['rpm_cruise'], 4)} | – |\n"
            f"| turning circle, 15° rudder at 1.54 m/s: tactical / steady diameter (m) | {fmt(v['tactical'], 3)} / "
            f"{fmt(v['steady'], 3)} | – |\n"
            f"| 5-DOF design model at U₀ = 1.54 m/s: m₁₁ … m₅₅ | {', '.join(fmt(x, 4) for x in v['m'])} | – |\n"
            f"| d₁₁ … d₅₅ | {', '.join(fmt(x, 4) for x in v['d'])} | – |\n"
            f"| ρg∇GM_L (N m), ℓ (m) | {fmt(v['wgml'], 4)}, {fmt(v['l'], 3)} | – |")


def block_fields() -> str:
    """Markdown table of every field of a vehicle file: unit, range, default, meaning (from ``FIELDS``)."""
    from auvtrack.vehicle.vehicle_file import DEFAULT_SOURCES, FIELDS

    head = "| field | unit | allowed | if absent | meaning |\n|---|---|---|---|---|"
    rows = []
    for key, f in FIELDS.items():
        allowed = f.range_text().removesuffix(f" {f.unit}") if f.unit else f.range_text()
        if f.size > 1:
            allowed = f"{f.size} numbers, each {allowed}"
        if f.allow_inf:
            allowed += " or inf"
        if key in DEFAULT_SOURCES:
            absent = fmt(f.default, 4)
        elif key in ("hull.mass", "hull.buoyancy"):
            absent = "neutral" if key == "hull.buoyancy" else "displaced mass"
        else:
            absent = "required"
        rows.append(f"| `{key}` | {f.unit or '-'} | {allowed} | {absent} | {f.text} |")
    return head + "\n" + "\n".join(rows)


def blocks() -> dict:
    """Generated block name -> renderer (all in docs/vehicles.md)."""
    return {"vehicle-file-fields": block_fields, "sea-trials": block_sea_trials, "truth-constants": block_constants,
            "torpedo-reduction": block_reduction, "remus600": block_remus600}


def render_text(text: str) -> str:
    """``text`` with every generated block of :func:`blocks` re-rendered (other generators' blocks left alone)."""
    table = blocks()

    def sub(m):
        name = m.group("name")
        if name not in table:
            return m.group(0)
        return m.group(1) + table[name]().rstrip() + "\n" + m.group(4)
    return BLOCK_RE.sub(sub, text)


def main(argv: list[str] | None = None) -> int:
    """``python -m tools.sea_trials render | check``."""
    args = sys.argv[1:] if argv is None else argv
    old = DOC.read_text()
    new = render_text(old)
    if args == ["render"]:
        if new != old:
            DOC.write_text(new)
        print("changed: " + ("docs/vehicles.md" if new != old else "nothing"))
        return 0
    if args == ["check"]:
        if new != old:
            print("stale generated blocks in docs/vehicles.md (python -m tools.sea_trials render)")
            return 1
        return 0
    print("usage: python -m tools.sea_trials render | check", file=sys.stderr)
    return 2


if __name__ == "__main__":  # pragma: no cover
    raise SystemExit(main())
