"""Standard manoeuvres of the 6-DOF truth plants: turning circle and zig-zag, metrics and figures.

Definitions (ITTC Recommended Procedures 7.5-04-02-01, Full Scale Manoeuvring Trials; Fossen
2021, Section 16.x on manoeuvring trials), measured from the execute time t0 (heading psi0,
position p0, unit heading vector h = (cos psi0, sin psi0), normal n = (-sin psi0, cos psi0)):

* *advance*: distance along h travelled when the heading has changed by 90 deg;
* *transfer*: distance along the turn's normal at 90 deg (positive towards the turn);
* *tactical diameter*: distance along the normal at 180 deg;
* *steady turning diameter*: 2 U / |r| averaged over the last turn recorded (after 360 deg);
* zig-zag psi_s / delta: the rudder is put over to +delta, reversed each time the heading
  change reaches +-psi_s; *overshoot* = largest heading change beyond psi_s after each reversal
  (first, second), *initial turning time* = time to the first reversal, *period* = time between
  the first and the third reversal.

The functions take logged arrays (t in s, positions in m, angles in rad) and return dicts of
plain floats (NaN where the record is too short), so they serve the example scenarios, the
model-gap study and the tests alike.
"""
from __future__ import annotations

import math

import numpy as np


def _crossing(t: np.ndarray, y: np.ndarray, level: float) -> float:
    """First time y(t) reaches ``level`` (linear interpolation), NaN if never."""
    idx = np.nonzero(y >= level)[0]
    if idx.size == 0:
        return math.nan
    i = int(idx[0])
    if i == 0:
        return float(t[0])
    return float(t[i - 1] + (level - y[i - 1]) * (t[i] - t[i - 1]) / (y[i] - y[i - 1]))


def turning_circle_metrics(t, x, y, psi, u, v, r, t0: float = 0.0) -> dict:
    """Advance, transfer, tactical and steady turning diameter of a turning circle.

    Parameters
    ----------
    t, x, y, psi, u, v, r : array_like
        Time (s), NED position (m), heading (rad), surge and sway (m/s), yaw rate (rad/s).
    t0 : float
        Execute time (rudder put over), s.

    Returns
    -------
    dict
        ``advance``, ``transfer``, ``tactical_diameter``, ``steady_diameter`` (m),
        ``time_90``, ``time_180`` (s), ``turn_direction`` (+1 starboard, -1 port).
    """
    t, x, y, psi, u, v, r = (np.asarray(a, float) for a in (t, x, y, psi, u, v, r))
    k = t >= t0
    t, x, y, psi, u, v, r = t[k], x[k], y[k], psi[k], u[k], v[k], r[k]
    dpsi = np.unwrap(psi) - psi[0]
    side = 1.0 if dpsi[-1] >= 0 else -1.0
    turned = side * dpsi
    h = np.array([math.cos(psi[0]), math.sin(psi[0])])
    n = side * np.array([-math.sin(psi[0]), math.cos(psi[0])])
    dp = np.stack([x - x[0], y - y[0]], axis=1)
    along, across = dp @ h, dp @ n
    t90, t180 = _crossing(t, turned, math.pi / 2), _crossing(t, turned, math.pi)

    def at(tc, s):
        return float(np.interp(tc, t, s)) if math.isfinite(tc) else math.nan
    t360 = _crossing(t, turned, 2 * math.pi)
    if math.isfinite(t360):
        last = t >= t360
        speed = np.hypot(u[last], v[last])
        steady = float(np.mean(2.0 * speed / np.abs(r[last])))
    else:
        steady = math.nan
    return {"advance": at(t90, along), "transfer": at(t90, across), "tactical_diameter": at(t180, across),
            "steady_diameter": steady, "time_90": t90, "time_180": t180, "turn_direction": side}


def zigzag_metrics(t, psi, delta_r, psi_switch: float, t0: float = 0.0) -> dict:
    """Overshoots, initial turning time and period of a zig-zag manoeuvre.

    Parameters
    ----------
    t, psi, delta_r : array_like
        Time (s), heading (rad), applied rudder angle (rad).
    psi_switch : float
        Heading change at which the rudder is reversed, rad (> 0).
    t0 : float
        Execute time, s.

    Returns
    -------
    dict
        ``initial_turning_time``, ``period`` (s), ``overshoot_1``, ``overshoot_2`` (rad), and
        ``reversals`` (number of rudder reversals in the record).
    """
    t, psi, delta_r = (np.asarray(a, float) for a in (t, psi, delta_r))
    k = t >= t0
    t, dpsi = t[k], np.unwrap(psi[k]) - psi[k][0]
    # reversal times: the heading change crosses +-psi_switch alternately (first towards the turn)
    turn = np.sign(np.mean(dpsi[: max(2, len(dpsi) // 20)])) or 1.0
    times, sign, start = [], turn, 0
    while True:
        seg = sign * dpsi[start:]
        tc = _crossing(t[start:], seg, psi_switch)
        if not math.isfinite(tc):
            break
        times.append(tc)
        start = int(np.searchsorted(t, tc)) + 1
        sign = -sign
        if start >= len(t):
            break
    over = []
    for j, tc in enumerate(times[:2]):
        s = turn if j % 2 == 0 else -turn
        end = times[j + 1] if j + 1 < len(times) else t[-1]
        m = (t >= tc) & (t <= end)
        over.append(float(np.max(s * dpsi[m]) - psi_switch) if np.any(m) else math.nan)
    over += [math.nan] * (2 - len(over))
    return {"initial_turning_time": float(times[0] - t[0]) if times else math.nan,
            "period": float(times[2] - times[0]) if len(times) >= 3 else math.nan,
            "overshoot_1": over[0], "overshoot_2": over[1], "reversals": len(times)}


# --- the study: both 6-DOF presets through the packaged example scenarios --------------------------

PRESETS = ("remus100_prestero", "remus100_fossen")
SCENARIOS = {"turning_circle": "remus100_turning_circle.toml", "zigzag": "remus100_zigzag.toml"}


def scenario_path(which: str):
    """Path of a packaged example scenario (``auvtrack/data/scenarios``): turning_circle or zigzag."""
    from importlib import resources
    return resources.files("auvtrack") / "data" / "scenarios" / SCENARIOS[which]


def rudder_within_limit(path, preset: str) -> list[str]:
    """Override that puts a scenario's rudder at the truth ``preset``'s fin limit when it is beyond it, else none.

    Parameters
    ----------
    path : path-like
        A packaged manoeuvre scenario (valid with its own plant preset).
    preset : str
        The 6-DOF truth it is flown on.

    Returns
    -------
    list of str
        ``["controller.delta_r=<limit>"]`` (the scenario's sign) or ``[]``.
    """
    from ..plant.sixdof.truth import actuator_values, truth_preset
    from ..scenario import load_scenario

    lim = actuator_values(truth_preset(preset)[0])["delta_max"]
    dr = load_scenario(path).controller.delta_r
    return [f"controller.delta_r={math.copysign(lim, dr)!r}"] if abs(dr) > lim else []


def run(out, *, quick: bool = False, progress: bool = False):
    """Run the turning circle and the zig-zag on both 6-DOF presets; write report, figures, results.

    Parameters
    ----------
    out : pathlib.Path
        Output folder (created).
    quick : bool, optional
        40 s instead of the scenarios' 120 s.
    progress : bool, optional
        Unused (few runs).

    Returns
    -------
    pathlib.Path
        The report's path.
    """
    from pathlib import Path

    from matplotlib.figure import Figure

    from ..scenario import load_scenario
    from ..simulation.compiling import compile_first
    from ..simulation.pipeline import prepare, run_prepared
    from ..report import Report, write_json

    compile_first([("open_loop_actuators", "6dof")], progress=progress)
    out = Path(out)
    runs, rows = {}, []
    for which in SCENARIOS:
        for preset in PRESETS:
            sets = [f"plant.preset={preset}"] + (["sim.duration=40"] if quick else [])
            sets += rudder_within_limit(scenario_path(which), preset)
            sc = load_scenario(scenario_path(which), sets)
            res = run_prepared(prepare(sc))
            ch = res.channels
            t0 = sc.controller.t_execute
            if which == "turning_circle":
                m = turning_circle_metrics(ch["t"], ch["x"], ch["y"], ch["psi"], ch["u"], ch["v"], ch["r"], t0)
            else:
                m = zigzag_metrics(ch["t"], ch["psi"], ch["delta_r"], sc.controller.zigzag_psi, t0)
            runs[(which, preset)] = (sc, ch)
            rows.append({"manoeuvre": which, "preset": preset, "status": res.status, **m,
                         "delta_r_deg": math.degrees(abs(sc.controller.delta_r)),
                         "speed_end": float(ch["u"][-1]), "max_theta_deg": float(np.degrees(np.abs(ch["theta"]).max())),
                         "max_phi_deg": float(np.degrees(np.abs(ch["phi"]).max()))})
    write_json(out / "results.json", {"rows": rows, "quick": quick})
    rep = Report(out, "Manoeuvres of the REMUS 100 truth models: turning circle and zig-zag")
    rep.paragraph("Open-loop (controller `open_loop_actuators`), from straight running at 1.5 m/s with the "
                  "propeller trimmed; rudder put over at 5 s. Scenarios: `scenarios/remus100_turning_circle.toml`, "
                  "`scenarios/remus100_zigzag.toml` (`--set plant.preset=...`); the rudder at most at the "
                  "preset's fin limit (P01: 13.6 deg). Metrics per ITTC 7.5-04-02-01. "
                  "P01's REMUS is open-loop unstable (docs/vehicles.md): it does not settle on a circle of the "
                  "rudder's making but spirals down, nose-down, losing speed.")
    fig = Figure(figsize=(10, 4.6))
    axes = fig.subplots(1, 2)
    for ax, preset in zip(axes, PRESETS):
        _, ch = runs[("turning_circle", preset)]
        ax.plot(ch["y"], ch["x"], lw=1.2)
        ax.set_aspect("equal", adjustable="datalim")
        ax.set_xlabel("east y (m)")
        ax.set_ylabel("north x (m)")
        ax.set_title(preset)
        ax.grid(True, alpha=0.3)
    fig.tight_layout()
    rep.figure(fig, "turning_circle", "turning circle tracks (rudder 15 deg at 5 s)")
    fig = Figure(figsize=(10, 5.6))
    axes = fig.subplots(2, 1, sharex=True)
    for preset in PRESETS:
        _, ch = runs[("zigzag", preset)]
        axes[0].plot(ch["t"], np.degrees(np.unwrap(ch["psi"]) - ch["psi"][0]), label=preset)
        axes[1].plot(ch["t"], np.degrees(ch["delta_r"]), label=preset)
    axes[0].set_ylabel("heading change (deg)")
    axes[1].set_ylabel("rudder (deg)")
    axes[1].set_xlabel("t (s)")
    for ax in axes:
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=8)
    fig.tight_layout()
    rep.figure(fig, "zigzag", "zig-zag 15/20: heading change and rudder angle")
    fig = Figure(figsize=(10, 6.4))
    axes = fig.subplots(3, 2, sharex="col")
    for col, which in enumerate(SCENARIOS):
        for preset in PRESETS:
            _, ch = runs[(which, preset)]
            axes[0, col].plot(ch["t"], np.degrees(ch["delta_r"]), label=preset)
            axes[1, col].plot(ch["t"], np.degrees(ch["delta_s"]), label=preset)
            axes[2, col].plot(ch["t"], ch["rpm"], label=preset)
        axes[0, col].set_title(which.replace("_", " "))
        axes[2, col].set_xlabel("t (s)")
    for row, label in enumerate(("rudder delta_r (deg)", "stern planes delta_s (deg)", "propeller (rpm)")):
        axes[row, 0].set_ylabel(label)
    for ax in axes.flat:
        ax.grid(True, alpha=0.3)
    axes[0, 0].legend(fontsize=8)
    fig.tight_layout()
    rep.figure(fig, "actuators", "fins and propeller of every run: rudder, stern planes (deg), propeller speed (rpm)")
    rep.heading("Turning circle")
    rep.table(["preset", "status", "advance (m)", "transfer (m)", "tactical diameter (m)", "steady diameter (m)",
               "speed at end (m/s)", "max \\|theta\\| (deg)"],
              [[r["preset"], r["status"], r["advance"], r["transfer"], r["tactical_diameter"], r["steady_diameter"],
                r["speed_end"], r["max_theta_deg"]] for r in rows if r["manoeuvre"] == "turning_circle"], digits=3)
    rep.heading("Zig-zag")
    rep.table(["preset", "status", "initial turning time (s)", "period (s)", "1st overshoot (deg)", "2nd overshoot (deg)",
               "speed at end (m/s)"],
              [[r["preset"], r["status"], r["initial_turning_time"], r["period"], math.degrees(r["overshoot_1"]),
                math.degrees(r["overshoot_2"]), r["speed_end"]] for r in rows if r["manoeuvre"] == "zigzag"], digits=3)
    for which in SCENARIOS:
        rep.scenario(scenario_path(which).read_text(encoding="utf-8"),
                     f"auvtrack/data/scenarios/{SCENARIOS[which]} (flown on each preset with --set plant.preset=...)")
    return rep.write()


def _spec():
    from .registry import StudySpec
    return StudySpec("manoeuvres", run, "turning circle and zig-zag of the 6-DOF REMUS 100 truth models "
                     "(ITTC metrics, standard figures)")


STUDY = _spec()
