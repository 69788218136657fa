"""Standard manoeuvres of the 6-DOF truth plants: turning circle and zig-zag, metrics and figures.

The metric definitions (ITTC 7.5-04-02-01) are :func:`auvtrack.simulation.manoeuvre.turning_circle_metrics`
and :func:`~auvtrack.simulation.manoeuvre.zigzag_metrics`, which ``auvtrack run`` also applies to every
open-loop run.
"""
from __future__ import annotations

import math

import numpy as np

from ..simulation.manoeuvre import turning_circle_metrics, zigzag_metrics

__all__ = ["turning_circle_metrics", "zigzag_metrics", "run", "scenario_path", "rudder_within_limit"]


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
