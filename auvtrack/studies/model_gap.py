"""``auvtrack study model-gap``: do the controllers survive a model they were not designed on?

Every controller is designed on the 5-DOF ``remus100`` preset (Prestero's REMUS 100 reduced at
the reference's speed, docs/vehicles.md) and flies three plants:

=============  ===================================================================
truth          what the controller does not know
=============  ===================================================================
``5dof``       nothing: its own design model (no uncertainty) -- the baseline
``prestero``   ``remus100_prestero``: roll, off-diagonal added mass, Munk moments, quadratic and
               cross-flow drag, lift, W != B, and real actuators (fins and propeller with lags and
               limits, through the control allocation)
``fossen``     ``remus100_fossen``: Fossen's spheroid model with its own hydrodynamics and actuators
=============  ===================================================================

over three references at a REMUS speed and turn radius both truths can fly (1.25 m/s, turns of
30 m radius or wider: a helix, a lawnmower survey with 60 m line spacing, a waypoint spline), each with and without an ocean current
(Gauss-Markov, mean (0.2, 0.1, 0) m/s NED, sigma 0.05 m/s, tau 60 s).  No disturbance force:
the model gap is the disturbance.  The vehicle starts 0.5 m beside the reference's start at the
reference speed, its propeller trimmed (:func:`auvtrack.plant.sixdof.truth.trim_rpm`).

Every controller flies each case twice (``gains``):

=============  ===================================================================
``designed``   the defaults on the ``remus100`` design vehicle: gains designed for its actuators'
               reach and ``saturation = "compensated"`` (docs/controllers.md, "Gains designed for
               the vehicle"; :mod:`auvtrack.control.design`)
``published``  the law's fixed default gains (Section 4's) and its published form
               (``saturation = "published"``; the PID without back-calculation)
=============  ===================================================================

Reported per run: status and failure cause (pitch, roll, envelope, divergence, ...), steady-state
tracking error (RMSE and max |e| over the second half), the navigation point's cross-track RMSE
and maximum against the path over the second half (the path-following metrics, docs/metrics.md),
and actuator usage: the time each actuator sits at its limit (fins at delta_max, propeller at
n_max) and the fins' rate (RMS and max |d delta / dt| from the log).  ``--quick`` runs the helix
without current for 20 s.

Only feasible tasks are flown: each (truth, reference, current) is assessed first
(:func:`auvtrack.feasibility.assess`, the current at its mean + 3 sigma); an infeasible one is
reported with the check that binds and its runs get status ``"infeasible"`` (not flown).  A
controller without a designed gain set or a saturation form (the LOS autopilot: its gains are
placed from the vehicle's model) flies each task once, as ``designed``.
"""
from __future__ import annotations

import math
from collections import Counter
from collections.abc import Sequence
from pathlib import Path

import numpy as np
from tqdm.auto import tqdm

from .registry import StudySpec
from ..report import Report, failure_cause, write_json

TRUTHS = {"5dof": None, "prestero": "remus100_prestero", "fossen": "remus100_fossen"}
CURRENT = {"kind": "current", "mean": [0.2, 0.1, 0.0], "sigma": [0.05, 0.05, 0.0], "tau": 60.0}
# Speed and turn radius within both truths' reach: Fossen's REMUS turns on ~21-24 m at full rudder
# (open loop, 1-1.5 m/s), so no turn is tighter than 30 m; P01's REMUS, 7 N positively buoyant,
# cannot hold depth with 15 deg stern planes much below ~1.1 m/s and its propeller (thrust scaled
# from P01's 3.86 N at 1500 rpm) tops out near 1.55 m/s, so every reference runs at 1.25 m/s.
SPEED = 1.25  # m/s
REFERENCES = {
    "helix": {"kind": "helix", "radius": 30.0, "omega": SPEED / 30.0, "climb": 0.05, "center": [-30.0, 0.0, 2.0]},
    "lawnmower": {"kind": "lawnmower", "start": [0.0, 0.0], "heading": 0.0, "leg_length": 80.0,
                  "spacing": 60.0, "legs": 3, "speed": SPEED, "depth": 5.0},
    "waypoints": {"kind": "waypoints", "points": [[0.0, 0.0, 2.0], [60.0, 0.0, 4.0], [110.0, 30.0, 6.0],
                                                  [110.0, 90.0, 6.0], [60.0, 120.0, 4.0]], "speed": SPEED},
}
ELL = 1.0  # m, virtual-point offset (remus100 preset)
GAINS = ("designed", "published")
"""The two gain sets every controller flies (module docstring)."""


def controllers() -> list[str]:
    """Tracking controllers to compare: every built-in whose registration says it tracks (no plug-ins)."""
    from ..benchmark.suite import tracking_kinds
    return tracking_kinds()


_every_controller = controllers  # run()'s default, under a name its ``controllers`` argument does not hide


def check_kinds(kinds: Sequence[str]) -> list[str]:
    """The controllers a run of the study flies (``--controllers``): registered kinds that track a reference.

    Parameters
    ----------
    kinds : sequence of str
        ``controller.kind`` values, e.g. ``["policy", "pid"]`` (a learned policy flies its default
        file, :data:`auvtrack.control.policy.DEFAULT_POLICY`).

    Returns
    -------
    list of str
        The kinds, in order, without repeats.

    Raises
    ------
    ValueError
        An empty list, or a kind that is not registered or does not track (one line naming the choices).
    """
    from ..control import CONTROLLERS

    out = list(dict.fromkeys(k.strip() for k in kinds if k.strip()))
    allowed = [k for k, spec in CONTROLLERS.items() if spec.tracks]
    bad = [k for k in out if k not in allowed]
    if not out or bad:
        raise ValueError(f"--controllers: {'no controller given' if not out else 'unknown or open-loop ' + ', '.join(bad)} "
                         f"(choose from {', '.join(allowed)})")
    return out


def start_pose(ref_spec: dict, ell: float = ELL) -> tuple[list[float], list[float]]:
    """(initial.eta, initial.nu): 0.5 m beside the reference's start, heading along it, at its speed."""
    from ..reference import build_reference
    p, v, _ = build_reference(ref_spec).evaluate(0.0)
    psi = math.atan2(v[1], v[0])
    speed = float(np.linalg.norm(v))
    theta = -math.atan2(v[2], math.hypot(v[0], v[1]))
    d = (math.cos(theta) * math.cos(psi), math.cos(theta) * math.sin(psi), -math.sin(theta))
    off = (-math.sin(psi) * 0.5, math.cos(psi) * 0.5, 0.0)  # 0.5 m to starboard of the path
    eta = [p[0] - ell * d[0] + off[0], p[1] - ell * d[1] + off[1], p[2] - ell * d[2], theta, psi]
    return eta, [speed, 0.0, 0.0, 0.0, 0.0]


def controller_section(controller: str, gains: str = "designed") -> dict:
    """The ``[controller]`` section of one gain set of :data:`GAINS`.

    Parameters
    ----------
    controller : str
        ``controller.kind``.
    gains : str
        ``"designed"``: the kind only (the defaults on the remus100: designed gains, compensated
        form); ``"published"``: the law's fixed defaults in its published form.

    Returns
    -------
    dict
        The section.
    """
    from ..control import CONTROLLERS

    if gains == "designed":
        return {"kind": controller}
    published = {"saturation": "published"} if "saturation" in CONTROLLERS[controller].params.model_fields else {}
    return {"kind": controller, "preset": "defaults", **published}


def scenario(controller: str, truth: str, reference: str, current: bool, duration: float,
             gains: str = "designed") -> dict:
    """The scenario (a dict for :func:`auvtrack.scenario.load_scenario`) of one run (``gains``: one of :data:`GAINS`)."""
    ref = REFERENCES[reference]
    eta, nu = start_pose(ref)
    sc = {
        "name": f"model-gap-{controller}-{gains}-{truth}-{reference}-{'current' if current else 'calm'}",
        "sim": {"duration": duration, "dt": 0.001, "log_dt": 0.01},
        "vehicle": {"preset": "remus100", "l": ELL},
        "reference": ref,
        "initial": {"eta": eta, "nu": nu},
        "controller": controller_section(controller, gains),
        "disturbance": [CURRENT] if current else [],
        "metrics": {"window": [duration / 2, duration]},
    }
    if TRUTHS[truth] is None:
        sc["uncertainty"] = {"C": 0.0, "D": 0.0, "M": 0.0, "G": 0.0}
    else:
        sc["plant"] = {"model": "6dof", "preset": TRUTHS[truth]}
    return sc


def gain_sets(controller: str) -> tuple[str, ...]:
    """The gain sets of :data:`GAINS` that differ for ``controller``.

    ``published`` only when its defaults are designed or it has a published saturation form.
    """
    from ..control.design import designable
    return GAINS if designable(controller) else GAINS[:1]


def jobs(quick: bool, kinds: Sequence[str] | None = None) -> list[tuple]:
    """Every (controller, truth, reference, current, gains) of the study (``kinds``: default :func:`controllers`)."""
    refs = ("helix",) if quick else tuple(REFERENCES)
    currents = (False,) if quick else (False, True)
    return [(k, t, r, c, g) for k in (controllers() if kinds is None else kinds) for g in gain_sets(k) for t in TRUTHS
            for r in refs for c in currents]


def feasibility(truth: str, reference: str, current: bool, duration: float):
    """:func:`auvtrack.feasibility.assess` of one task (the controller does not enter)."""
    from ..feasibility import assess
    return assess(scenario(controllers()[0], truth, reference, current, duration))


def binding_check(f) -> str:
    """The check of a :class:`~auvtrack.feasibility.Feasibility` that uses most of its limit, in words."""
    c = max(f.checks, key=lambda k: k.usage)
    usage = "no steady state" if not math.isfinite(c.usage) else f"{100 * c.usage:.0f}% of {c.limit}"
    return f"{c.name}: {usage}"


def infeasible_row(job: tuple, reason: str) -> dict:
    """The row of a run not flown because its task is infeasible."""
    kind, truth, ref, current, gains = job
    return {"controller": kind, "gains": gains, "truth": truth, "reference": ref, "current": current,
            "status": "infeasible", "cause": reason, "fail_time": None, "rmse_late": None, "max_e_late": None,
            "max_theta_deg": None, "duration_run": 0.0}


def _at_limit(x: np.ndarray, limit: float) -> np.ndarray:
    return np.abs(x) >= limit * (1.0 - 1e-9)


def summarise(job: tuple, res, limits: dict | None) -> dict:
    """One result row: status, cause, tracking error, path-following errors, actuator usage."""
    kind, truth, ref, current, gains = job
    ch = res.channels
    t = ch["t"]
    T = t[-1] if t.size else 0.0
    row = {"controller": kind, "gains": gains, "truth": truth, "reference": ref, "current": current,
           "status": res.status, "cause": failure_cause(res), "fail_time": res.failure["time"] if res.failure else None}
    if t.size == 0:  # stopped before the first logged row
        row.update(rmse_late=None, max_e_late=None, max_theta_deg=None)
        row["duration_run"] = 0.0
        return row
    e = np.sqrt(ch["ex"] ** 2 + ch["ey"] ** 2 + ch["ez"] ** 2)
    late = t >= t[-1] / 2
    row["rmse_late"] = float(np.sqrt(np.mean(e[late] ** 2)))
    row["max_e_late"] = float(e[late].max())
    row["max_theta_deg"] = float(np.degrees(np.abs(ch["theta"]).max()))
    if limits is not None and "delta_r" in ch:
        dt = np.diff(t)
        for name, lim in (("delta_r", limits["delta_max"]), ("delta_s", limits["delta_max"]), ("rpm", limits["n_max"])):
            row[f"sat_frac_{name}"] = float(np.mean(_at_limit(ch[name], lim)))
        for name in ("delta_r", "delta_s"):
            rate = np.abs(np.diff(ch[name])) / dt if dt.size else np.zeros(1)
            row[f"rate_rms_{name}"] = float(np.sqrt(np.mean(rate ** 2)))
            row[f"rate_max_{name}"] = float(rate.max())
        row["max_phi_deg"] = float(np.degrees(np.abs(ch["phi"]).max()))
    for j in "uqr":  # the engine's time with tau_j unproducible (allocation's saturation flags), s
        v = res.metrics.get(f"t_sat_tau_{j}")
        row[f"t_sat_tau_{j}"] = float(v) if v is not None and math.isfinite(v) else None
    for k in ("xtrack_rmse", "xtrack_max", "vtrack_rmse", "along_rmse"):  # the navigation point on the path
        v = res.metrics.get(k)
        row[f"{k}_late"] = float(v) if v is not None and math.isfinite(v) else None
    row["duration_run"] = float(T)
    return row


def run(out: Path, *, quick: bool = False, progress: bool = False, controllers: Sequence[str] | None = None) -> Path:
    """Run the model-gap study and write ``report.md``, ``results.json`` and ``runs.csv``.

    Parameters
    ----------
    out : pathlib.Path
        Output folder (created).
    quick : bool, optional
        The helix without current, 20 s runs (CI) instead of every reference with and without
        current, 150 s.
    progress : bool, optional
        Show a progress bar.
    controllers : sequence of str, optional
        The controller kinds to fly (:func:`check_kinds`; ``auvtrack study model-gap --controllers
        policy,pid``); default every built-in tracking controller.

    Returns
    -------
    pathlib.Path
        The report's path.
    """
    from ..scenario import load_scenario
    from ..simulation.compiling import compile_first
    from ..simulation.pipeline import prepare, run_prepared

    kinds = _every_controller() if controllers is None else check_kinds(controllers)
    compile_first([(c, p) for c in kinds for p in ("5dof", "6dof")], progress=progress)
    out = Path(out)
    duration = 20.0 if quick else 150.0
    tasks = {}
    for _, truth, ref, current, _ in jobs(quick, kinds):
        if (truth, ref, current) not in tasks:
            tasks[truth, ref, current] = feasibility(truth, ref, current, duration)
    rows = []
    for job in tqdm(jobs(quick, kinds), disable=not progress, desc="model-gap"):
        kind, truth, ref, current, gains = job
        f = tasks[truth, ref, current]
        if f.verdict == "infeasible":
            rows.append(infeasible_row(job, binding_check(f)))
            continue
        sc = load_scenario(scenario(kind, truth, ref, current, duration, gains))
        res = run_prepared(prepare(sc))
        limits = sc.plant.actuator_limits() if hasattr(sc.plant, "actuator_limits") else None  # 6-DOF truths only
        rows.append(summarise(job, res, limits))
    feasible = [{"truth": t, "reference": r, "current": c, "verdict": f.verdict,
                 "binding": binding_check(f) if f.checks else None} for (t, r, c), f in tasks.items()]
    write_json(out / "results.json", {"duration_s": duration, "quick": quick, "rows": rows, "tasks": feasible,
                                      "references": {k: REFERENCES[k] for k in {r["reference"] for r in rows}},
                                      "current": CURRENT})
    _write_csv(out / "runs.csv", rows)
    rep = Report(out, "Model gap: controllers designed on the 5-DOF REMUS 100, flown on 6-DOF truth models")
    rep.paragraph(
        f"Design model: `remus100` (5-DOF, reduced at the reference's speed). Truths: its own 5-DOF model "
        f"(no uncertainty), `remus100_prestero`, `remus100_fossen` (6-DOF, fins and propeller through the "
        f"control allocation). Gains: `designed` (the defaults on this vehicle: designed for its actuators' "
        f"reach, compensated form) and `published` (the law's fixed defaults, published form). {duration:g} s "
        f"runs; errors and the time with tau unproducible (the allocation's saturation flags) over the second "
        f"half; the navigation point's path-following errors over the second half; fins / rpm at limit and fin rates over the whole run (fractions of the logged samples). Current: "
        f"Gauss-Markov, mean {CURRENT['mean']} m/s, sigma {CURRENT['sigma']} m/s.")
    rep.heading("Tasks: feasibility")
    rep.paragraph("Each task assessed before it is flown (`auvtrack.feasibility`, the current at mean + 3 sigma); "
                  "infeasible tasks are not flown.")
    rep.table(["truth", "reference", "current", "verdict", "binding check"],
              [[f["truth"], f["reference"], "yes" if f["current"] else "no", f["verdict"], f["binding"] or "–"]
               for f in feasible])
    rep.heading("Failures by cause")
    rep.table(["controller", "gains", "truth", "runs flown", "failed", "causes"], _failure_table(rows))
    rep.heading("Runs")
    rep.table(["controller", "gains", "truth", "reference", "current", "status", "rmse late (m)",
               "max \\|e\\| late (m)", "xtrack rmse / max late (m)",
               "max \\|theta\\| (deg)", "max \\|phi\\| (deg)", "tau unproducible u / q / r (s)", "fins at limit (r / s)",
               "rpm at limit", "fin rate rms r / s (rad/s)"],
              [[r["controller"], r.get("gains", "designed"), r["truth"], r["reference"], "yes" if r["current"] else "no",
                _status_cell(r),
                r["rmse_late"], r["max_e_late"], _pair(r.get("xtrack_rmse_late"), r.get("xtrack_max_late")),
                r["max_theta_deg"], r.get("max_phi_deg"),
                " / ".join("–" if r.get(f"t_sat_tau_{j}") is None else f"{r[f't_sat_tau_{j}']:.3g}" for j in "uqr"),
                _pair(r.get("sat_frac_delta_r"), r.get("sat_frac_delta_s")), r.get("sat_frac_rpm"),
                _pair(r.get("rate_rms_delta_r"), r.get("rate_rms_delta_s"))] for r in rows], digits=3)
    return rep.write()


def _status_cell(r: dict) -> str:
    if r["status"] == "failed":
        return f"failed: {r['cause']} at {r['fail_time']:.3g} s"
    return r["status"]


def _pair(a, b) -> str:
    return "–" if a is None else f"{a:.3g} / {b:.3g}"


def _failure_table(rows: list[dict]) -> list[list]:
    out = []
    for kind in dict.fromkeys(r["controller"] for r in rows):
        for gains in GAINS:
            for truth in TRUTHS:
                mine = [r for r in rows if r["controller"] == kind and r.get("gains", "designed") == gains
                        and r["truth"] == truth]
                if not mine:
                    continue
                flown = [r for r in mine if r["status"] != "infeasible"]
                if not flown:
                    continue
                causes = Counter(r["cause"] for r in flown if r["status"] != "ok")
                out.append([kind, gains, truth, len(flown), sum(causes.values()),
                            ", ".join(f"{c} × {n}" for c, n in sorted(causes.items())) or "–"])
    return out


def _write_csv(path: Path, rows: list[dict]) -> None:
    import csv
    keys = list(dict.fromkeys(k for r in rows for k in r))
    with open(path, "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=keys)
        w.writeheader()
        w.writerows(rows)


STUDY = StudySpec("model-gap", run, "controllers designed on the 5-DOF REMUS 100 flown on 6-DOF truth "
                  "models (Prestero, Fossen), designed and published gains: failures by cause, tracking, "
                  "distance to the path, actuator usage", options=("controllers",))
