"""``auvtrack study ablation``: which ingredient keeps the vehicle alive under a large pulse?

Configurations: envelope {rigid, reactive, proactive} x estimator {none, printed, omega,
effective} for the FXTNTSMC, the FXTNTSMC without an envelope (estimator none or effective:
without an envelope Omega = G = 1 and the three adaptive laws are the same law), and the FTSMC
baseline, which has neither envelope nor estimator.

For each configuration the study

1. runs the paper's Section 4 as it is (status, failure cause, metrics);
2. adds a force/moment pulse ``amplitude * direction`` to Section 4 and **scans** the survival
   of the amplitude (:func:`scan_survival`): a geometric grid from ``a_min`` to ``a_max`` first,
   then geometric bisection of every transition between neighbouring grid points to a relative
   tolerance.  Survival is not monotone in the amplitude (a configuration may fail at one
   amplitude and survive a larger one), so the result is the set of survival intervals, with
   ``first_failure`` (the smallest failing amplitude found) and ``survives_up_to`` (the largest
   amplitude below it that survived);
3. reports the metrics at a fixed reference amplitude, over the window from the pulse onset.

The pulse starts by default at t = 20 s, after the envelope's prescribed time T = 15 s: the
baseline envelope has shrunk to rho_inf = 5 mm, the tight phase in which a rigid envelope
leaves no room and the paper's risk monitor is supposed to act.  It lasts 1 s (long compared
with the closed loop's sub-second transients, short compared with the horizon) and the run
continues for 19 s so that the internal (pitch, sway, heave) dynamics can recover or fail.
Directions, reported separately: sway force (unactuated; the virtual point is steered through
yaw), heave force (unactuated; excites the pitch internal dynamics) and surge force with pitch
and yaw moments (actuated).  ``--pulse F1,F2,F3,F4,F5`` replaces them by one direction and
``--pulse-start T`` moves the onset.

Conditions: ``continuous`` control, as in the paper's analysis, and ``sampled`` control at
500 Hz (zero-order hold, as a digital controller would run): between samples a barrier
controller cannot react, so the envelope can be crossed.  Survival is "the run reaches the
horizon without a failure" (envelope violation, pitch limit, non-finite state, state limit).
"""
from __future__ import annotations

import math
import re
import warnings
from dataclasses import asdict, dataclass, field, replace
from pathlib import Path
from typing import Any, Callable, Sequence

import numpy as np

from ..batch.runner import stoppable_pool
from ..scenario import load_scenario, paper_scenario_path
from ..simulation.compiling import compile_first
from ..simulation.pipeline import prepare, run_prepared
from ..simulation.result import Result
from .registry import StudySpec, kinds_in
from ..report import Report, failure_cause, fmt, write_json

ENVELOPE_KINDS = ("none", "rigid", "reactive", "proactive")
ESTIMATOR_KINDS = ("none", "printed", "omega", "effective")
DEFAULT_ESTIMATOR = "effective"
DIRECTIONS: dict[str, tuple[float, ...]] = {
    "sway": (0.0, 1.0, 0.0, 0.0, 0.0),
    "heave": (0.0, 0.0, 1.0, 0.0, 0.0),
    "surge+moments": (1.0, 0.0, 0.0, 0.25, 0.25),
}
"""Pulse directions (F_u, F_v, F_w in N, M_q, M_r in N m per unit amplitude)."""
CONDITIONS = {"continuous": [], "sampled": ["sim.control_rate=500"]}
NOMINAL_KEYS = ("status", "cause", "fail_time", "settle_1cm", "settle_1mm", "max_abs_e", "max_abs_tau",
                "tv_tau")


@dataclass(frozen=True)
class Config:
    """One controller configuration: a label and its scenario overrides."""

    label: str
    overrides: tuple[str, ...]


def _fx(env: str, est: str) -> Config:
    return Config(f"fxtntsmc/{env}/{est}", ("controller.kind=fxtntsmc", f"envelope.kind={env}",
                                            f"estimator.kind={est}"))


def configurations() -> list[Config]:
    """The FXTNTSMC configurations (envelope x estimator) and the FTSMC baseline.

    Without an envelope Omega = G = 1, so the printed, omega and effective laws coincide: that
    envelope has two configurations (estimator none and effective), see :func:`config_label`.
    """
    out = [_fx("none", "none"), _fx("none", DEFAULT_ESTIMATOR)]
    out += [_fx(env, est) for env in ENVELOPE_KINDS[1:] for est in ESTIMATOR_KINDS]
    out.append(Config("ftsmc", ("controller.kind=ftsmc",)))
    return out


def config_label(env: str, est: str) -> str:
    """Label of the configuration that runs (envelope ``env``, estimator ``est``).

    Without an envelope every adaptive law is the same law; its configuration is
    ``fxtntsmc/none/effective``.
    """
    if env == "none" and est != "none":
        est = DEFAULT_ESTIMATOR
    return f"fxtntsmc/{env}/{est}"


@dataclass(frozen=True)
class AblationSettings:
    """Everything that defines a run of the study (``quick`` shrinks it).

    ``directions`` are (name, 5-vector) pairs; the horizon of a pulse run is
    ``pulse_start + pulse_duration + recovery``.  The amplitude grid has ``per_decade`` points
    per decade from ``a_min`` to ``a_max``; every transition is bisected until
    ``hi / lo - 1 <= rtol``.
    """

    pulse_start: float = 20.0
    pulse_duration: float = 1.0
    recovery: float = 19.0
    nominal_duration: float = 100.0
    a_min: float = 1.0
    a_max: float = 1.0e4
    per_decade: int = 12
    rtol: float = 0.05
    a_ref: float = 100.0
    directions: tuple[tuple[str, tuple[float, ...]], ...] = tuple(DIRECTIONS.items())
    conditions: tuple[str, ...] = ("continuous", "sampled")
    configs: tuple[str, ...] = ()  # empty: all

    @property
    def horizon(self) -> float:
        """End time of a pulse run (s)."""
        return self.pulse_start + self.pulse_duration + self.recovery

    @classmethod
    def quick(cls) -> "AblationSettings":
        """CI-sized: FXTNTSMC with envelopes none, rigid and proactive and the default estimator;
        heave only, continuous control, a coarse grid and tolerance."""
        return cls(recovery=3.0, nominal_duration=20.0, a_min=10.0, a_max=1000.0, per_decade=3, rtol=0.5,
                   directions=(("heave", DIRECTIONS["heave"]),), conditions=("continuous",),
                   configs=tuple(config_label(e, DEFAULT_ESTIMATOR) for e in ("none", "rigid", "proactive")))


def parse_pulse(text: str) -> tuple[float, ...]:
    """The ``--pulse F1,F2,F3,F4,F5`` option: five finite numbers, not all zero.

    Raises
    ------
    ValueError
        One line naming the option and what it accepts.
    """
    parts = [p.strip() for p in str(text).split(",")]
    try:
        vec = tuple(float(p) for p in parts)
    except ValueError:
        vec = ()
    if len(vec) != 5 or not all(math.isfinite(v) for v in vec):
        raise ValueError(f"--pulse: expected 5 comma-separated finite numbers F1,F2,F3,F4,F5 "
                         f"(N, N, N, N m, N m per unit amplitude) (got {text!r})")
    if not any(vec):
        raise ValueError(f"--pulse: the direction must not be zero (got {text!r})")
    return vec


def settings_for(quick: bool = False, pulse: str | Sequence[float] | None = None,
                 pulse_start: float | None = None) -> AblationSettings:
    """Default or quick settings with the ``--pulse`` / ``--pulse-start`` options applied.

    Raises
    ------
    ValueError
        For a bad ``pulse`` or a ``pulse_start`` that is not a finite number >= 0.
    """
    st = AblationSettings.quick() if quick else AblationSettings()
    if pulse is not None:
        vec = parse_pulse(pulse) if isinstance(pulse, str) else parse_pulse(",".join(map(str, pulse)))
        st = replace(st, directions=((f"pulse [{', '.join(f'{v:g}' for v in vec)}]", vec),))
    if pulse_start is not None:
        if isinstance(pulse_start, bool) or not isinstance(pulse_start, (int, float)) or not (
                math.isfinite(pulse_start) and pulse_start >= 0):
            raise ValueError(f"--pulse-start: must be a finite number >= 0 s (got {pulse_start!r})")
        st = replace(st, pulse_start=float(pulse_start))
        _check_horizon(st)
    return st


def _check_horizon(st: AblationSettings) -> None:
    """Refuse a pulse onset whose runs the scenario would refuse (run plan, time grid), naming the option."""
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            prepare(load_scenario(paper_scenario_path(), {"sim.duration": st.horizon}))  # the run's length alone
            prepare(_scenario(configurations()[0], st.conditions[0], st.horizon, st.directions[0][1], st,
                              window=(st.pulse_start, st.horizon)))
    except ValueError as exc:
        reason = re.sub(r"^(?:<dict>|\S*\.toml): ", "", " ".join(str(exc).split()))  # without the file's name
        reason = re.sub(r" \((?:set by override|raise it deliberately)[^)]*\)", "", reason)  # not the user's
        raise ValueError(f"--pulse-start: a pulse at {st.pulse_start:g} s makes each pulse run last "
                         f"{st.horizon:g} s, which is refused: {reason}") from None


# ------------------------------------------------------------------ survival scan
@dataclass
class Probe:
    """One evaluation of the survival function."""

    amplitude: float
    survived: bool
    cause: str | None = None
    time: float | None = None
    max_theta_deg: float | None = None  # largest |pitch| of the run (deg), when the survival function gives it


@dataclass
class Survival:
    """Outcome of :func:`scan_survival`.

    Attributes
    ----------
    kind : {"bracketed", "survives_cap", "fails_min"}
        ``bracketed``: survives ``a_min`` and fails somewhere in range; ``survives_cap``: no
        probe failed; ``fails_min``: failed already at ``a_min``.
    first_failure : float or None
        Smallest failing amplitude found (None if none failed).
    cause, fail_time : str or None, float or None
        Failure cause and time at ``first_failure``.
    survives_up_to : float or None
        Largest surviving amplitude below ``first_failure`` (every probe up to it survived);
        ``a_max``-bounded; None for ``fails_min``.
    intervals : list of dict
        Every survival interval: ``{"lo", "hi"}`` (first and last surviving probe) and
        ``"failed_below"``, ``"failed_above"`` (the failing probes just outside, or None at the
        ends of the range), in increasing amplitude.
    monotone : bool
        True when every surviving probe lies below every failing probe.
    largest_survived : float or None
        Largest surviving amplitude overall (above ``first_failure`` when not monotone).
    probes : list of Probe
        Every evaluation, in the order made (grid first, then bisections).
    """

    kind: str
    first_failure: float | None
    cause: str | None
    fail_time: float | None
    survives_up_to: float | None
    intervals: list[dict[str, Any]]
    monotone: bool
    largest_survived: float | None
    probes: list[Probe] = field(default_factory=list)


def amplitude_grid(a_min: float, a_max: float, per_decade: int) -> list[float]:
    """Geometric grid from ``a_min`` to ``a_max`` (both included), ``per_decade`` steps per decade or finer."""
    if not (0 < a_min <= a_max and math.isfinite(a_max)):
        raise ValueError(f"need 0 < a_min <= a_max < inf (got a_min={a_min!r}, a_max={a_max!r})")
    if not (isinstance(per_decade, int) and per_decade >= 1):
        raise ValueError(f"per_decade must be an integer >= 1 (got {per_decade!r})")
    if a_min == a_max:
        return [float(a_min)]
    n = max(1, math.ceil(math.log10(a_max / a_min) * per_decade - 1e-9))
    g = np.geomspace(a_min, a_max, n + 1)
    g[0], g[-1] = a_min, a_max
    return [float(x) for x in g]


def scan_survival(survives: Callable[[float], tuple[bool, str | None, float | None]], a_min: float,
                  a_max: float, *, per_decade: int = 12, rtol: float = 0.05,
                  max_probes: int = 1000) -> Survival:
    """Survival of every amplitude in ``[a_min, a_max]``: grid scan, then bisection of each transition.

    Parameters
    ----------
    survives : callable
        ``survives(a) -> (ok, cause, time)`` or ``(ok, cause, time, max_theta_deg)``; ``cause``
        and ``time`` describe the failure.
    a_min, a_max : float
        Search range, ``0 < a_min <= a_max``.
    per_decade : int, optional
        Grid points per decade (the grid ratio is at most ``10 ** (1 / per_decade)``).
    rtol : float, optional
        Bisect each grid cell whose ends differ until ``hi / lo - 1 <= rtol`` (geometric
        midpoints ``sqrt(lo hi)``).
    max_probes : int, optional
        Safety cap on the number of evaluations.

    Returns
    -------
    Survival
        Survival intervals, first failure and every probe.  A survival (or failure) window that
        lies strictly between two neighbouring grid points can be missed: the grid ratio is the
        resolution of the scan.
    """
    if not rtol > 0:
        raise ValueError(f"rtol must be > 0 (got {rtol!r})")
    grid = amplitude_grid(a_min, a_max, per_decade)
    probes: list[Probe] = []

    def probe(a: float) -> Probe:
        ok, cause, t, *extra = survives(a)
        p = Probe(float(a), bool(ok), None if ok else cause, None if ok else t, *extra[:1])
        probes.append(p)
        return p

    pts = [probe(a) for a in grid]
    for lo, hi in zip(pts[:-1], pts[1:]):
        while lo.survived != hi.survived and hi.amplitude / lo.amplitude - 1.0 > rtol and len(probes) < max_probes:
            mid = probe(math.sqrt(lo.amplitude * hi.amplitude))
            if mid.survived == lo.survived:
                lo = mid
            else:
                hi = mid
    return summarize(probes)


def summarize(probes: Sequence[Probe]) -> Survival:
    """Survival intervals, first failure and monotonicity of a set of probes (any order)."""
    ordered = sorted(probes, key=lambda p: p.amplitude)
    intervals: list[dict[str, Any]] = []
    prev_fail: float | None = None
    cur: dict[str, Any] | None = None
    for p in ordered:
        if p.survived:
            if cur is None:
                cur = {"lo": p.amplitude, "hi": p.amplitude, "failed_below": prev_fail, "failed_above": None}
                intervals.append(cur)
            cur["hi"] = p.amplitude
        else:
            if cur is not None:
                cur["failed_above"] = p.amplitude
            cur, prev_fail = None, p.amplitude
    fails = [p for p in ordered if not p.survived]
    first = fails[0] if fails else None
    ok = [p.amplitude for p in ordered if p.survived]
    if first is None:
        kind, upto = "survives_cap", (ok[-1] if ok else None)
    elif ordered[0] is first:
        kind, upto = "fails_min", None
    else:
        kind, upto = "bracketed", max(a for a in ok if a < first.amplitude)
    monotone = first is None or not ok or max(ok) < first.amplitude
    return Survival(kind, None if first is None else first.amplitude, None if first is None else first.cause,
                    None if first is None else first.time, upto, intervals, monotone,
                    max(ok) if ok else None, list(probes))


def compare(a: dict[str, Any], b: dict[str, Any]) -> int:
    """Compare two survival records on their first transition: +1 if ``a`` provably survives longer.

    ``a`` is better when it survives every amplitude up to at least ``b``'s first failure
    (``a["survives_up_to"] >= b["first_failure"]``); -1 for the converse; 0 when the brackets
    overlap (equal within the tolerance) or neither failed.
    """
    ua, ub = a["survives_up_to"] or 0.0, b["survives_up_to"] or 0.0
    if b["first_failure"] is not None and ua >= b["first_failure"]:
        return 1
    if a["first_failure"] is not None and ub >= a["first_failure"]:
        return -1
    return 0


# ------------------------------------------------------------------ runs
def _scenario(cfg: Config, condition: str, duration: float, pulse: tuple[float, ...] | None,
              st: AblationSettings, window: tuple[float, float] | None = None, log_dt: float | None = None):
    ov = [*cfg.overrides, *CONDITIONS[condition], f"sim.duration={duration:g}"]
    if window is not None:
        ov.append(f"metrics.window=[{window[0]:g}, {window[1]:g}]")
    if log_dt is not None:
        ov.append(f"sim.log_dt={log_dt:g}")
    sc = load_scenario(paper_scenario_path(), ov)
    if pulse is None:
        return sc
    d = sc.to_dict()
    d["disturbance"] = [*d["disturbance"], {"kind": "pulse", "start": st.pulse_start,
                                            "duration": st.pulse_duration, "force": list(pulse)}]
    return load_scenario(d)


def _run(sc) -> Result:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return run_prepared(prepare(sc))


def band_gain_ratio(res: Result, t_from: float = 0.0) -> dict[str, Any] | None:
    """G / Omega over the logged samples inside the risk monitor's band (0 < g < 1), all axes.

    The ratio is the logged ``gain_ratio_*`` channel (the controller's G and Omega at the same instant).

    Returns ``{"samples", "min", "median", "max"}`` or None when the run logs no effective gain
    or never enters the band after ``t_from``.
    """
    ch = res.channels
    if "gain_ratio_x" not in ch or not ch["t"].size:
        return None
    sel = ch["t"] >= t_from
    vals = []
    for a in "xyz":
        g = ch[f"g_{a}"][sel]
        band = (g > 0) & (g < 1)
        vals.append(ch[f"gain_ratio_{a}"][sel][band])
    v = np.concatenate(vals)
    if not v.size:
        return None
    return {"samples": int(v.size), "min": float(v.min()), "median": float(np.median(v)), "max": float(v.max())}


def _summary(res: Result, t_from: float = 0.0) -> dict[str, Any]:
    """Status, cause and the headline metrics of one run (max over axes/inputs)."""
    m = res.metrics
    out: dict[str, Any] = {
        "status": res.status, "cause": failure_cause(res),
        "fail_time": res.failure["time"] if res.failure else None,
        "settle_1cm": max(m[f"settle_1cm_{a}"] for a in "xyz"),
        "settle_1mm": max(m[f"settle_1mm_{a}"] for a in "xyz"),
        "max_abs_e": max(m[f"max_abs_{a}"] for a in "xyz"),
        "rmse": max(m[f"rmse_{a}"] for a in "xyz"),
        "max_abs_tau": max(m[f"max_abs_tau_{j}"] for j in ("u", "q", "r")),
        "energy_tau": sum(m[f"energy_tau_{j}"] for j in ("u", "q", "r")),
        "tv_tau": sum(m[f"tv_tau_{j}"] for j in ("u", "q", "r")),
    }
    ch = res.channels
    if "g_x" in ch and ch["t"].size:
        sel = ch["t"] >= t_from
        if sel.any():
            out["max_g"] = float(np.nanmax([np.nanmax(ch[f"g_{a}"][sel]) for a in "xyz"]))
            wid = np.concatenate([ch[f"rho_{a}"][sel] - ch[f"rho1_{a}"][sel] for a in "xyz"])
            wid = wid[np.isfinite(wid)]  # envelope "none" logs NaN: no widening, and no All-NaN warning
            out["max_widening"] = float(wid.max()) if wid.size else None
    return out


def _scan_job(job: tuple[Config, str, str, tuple[float, ...], AblationSettings]) -> dict[str, Any]:
    cfg, condition, direction, vec, st = job

    def survives(a: float):
        res = _run(_scenario(cfg, condition, st.horizon, tuple(a * x for x in vec), st))
        th = res.channels["theta"]
        return (res.ok, failure_cause(res), (res.failure or {}).get("time"),
                float(np.degrees(np.nanmax(np.abs(th)))) if th.size else None)

    sv = scan_survival(survives, st.a_min, st.a_max, per_decade=st.per_decade, rtol=st.rtol)
    return {"config": cfg.label, "condition": condition, "direction": direction, **asdict(sv)}


def _nominal_job(job: tuple[Config, str, AblationSettings]) -> dict[str, Any]:
    cfg, condition, st = job
    res = _run(_scenario(cfg, condition, st.nominal_duration, None, st))
    return {"config": cfg.label, "condition": condition, **_summary(res)}


def _reference_job(job: tuple[Config, str, str, tuple[float, ...], AblationSettings]) -> dict[str, Any]:
    cfg, condition, direction, vec, st = job
    pulse = tuple(st.a_ref * x for x in vec)
    res = _run(_scenario(cfg, condition, st.horizon, pulse, st, window=(st.pulse_start, st.horizon)))
    return {"config": cfg.label, "condition": condition, "direction": direction, "amplitude": st.a_ref,
            **_summary(res, st.pulse_start)}


def _pool_map(fn, jobs: Sequence, progress: bool, desc: str) -> list:
    from tqdm.auto import tqdm

    with stoppable_pool() as pool:  # the compiled kernel releases the GIL; a stop drops the queued runs
        return list(tqdm(pool.map(fn, jobs), total=len(jobs), disable=not progress, desc=desc))


# ------------------------------------------------------------------ report
def survival_text(r: dict[str, Any]) -> str:
    """``survives_up_to – first_failure`` of one record, or its special case."""
    if r["kind"] == "survives_cap":
        return f"> {fmt(r['survives_up_to'])} (cap)"
    if r["kind"] == "fails_min":
        return f"< {fmt(r['first_failure'])}"
    return f"{fmt(r['survives_up_to'])} – {fmt(r['first_failure'])}"


def pitch_at(r: dict[str, Any], amplitude: float | None) -> float | None:
    """Largest |pitch| (deg) of the probe of record ``r`` at ``amplitude`` (None if not recorded)."""
    return next((p.get("max_theta_deg") for p in r["probes"] if p["amplitude"] == amplitude), None)


def intervals_text(r: dict[str, Any]) -> str:
    """Every survival interval of one record, e.g. ``[1, 906]; [1107, 1412]``."""
    if not r["intervals"]:
        return "none"
    return "; ".join(f"[{fmt(iv['lo'])}, {fmt(iv['hi'])}" + ("] (cap)" if iv["failed_above"] is None else "]")
                     for iv in r["intervals"])


def _figure(scans: list[dict[str, Any]], st: AblationSettings):
    from matplotlib.figure import Figure

    dirs = [d for d, _ in st.directions]
    labels = list(dict.fromkeys(r["config"] for r in scans))
    fig = Figure(figsize=(5.0 * len(st.conditions), (0.3 * len(labels) + 1.2) * len(dirs)))
    axes = fig.subplots(len(dirs), len(st.conditions), sharex=True, squeeze=False)
    colors = {None: "tab:gray", "envelope_violation": "tab:red", "pitch_limit": "tab:blue",
              "nonfinite": "tab:purple", "state_limit": "tab:orange"}
    for row, d in enumerate(dirs):
        for col, c in enumerate(st.conditions):
            ax = axes[row][col]
            recs = {r["config"]: r for r in scans if r["condition"] == c and r["direction"] == d}
            for i, lab in enumerate(labels):
                r = recs.get(lab)
                if r is None:
                    continue
                for iv in r["intervals"]:
                    ax.plot([iv["lo"], iv["hi"]], [i, i], color="tab:green", lw=5, solid_capstyle="butt")
                fails = [p for p in r["probes"] if not p["survived"]]
                for p in fails:
                    ax.plot(p["amplitude"], i, "|", color=colors.get(p["cause"], "tab:gray"), ms=7)
            ax.set_xscale("log")
            ax.set_xlim(st.a_min / 1.5, st.a_max * 1.5)
            ax.set_title(f"{d} pulse, {c} control", fontsize=9)
            ax.set_yticks(range(len(labels)), labels if col == 0 else [""] * len(labels), fontsize=7)
            ax.invert_yaxis()
            if row == len(dirs) - 1:
                ax.set_xlabel("pulse amplitude A (N)")
    fig.suptitle("green: survived; ticks: failed probes (red envelope violation, blue pitch limit, "
                 "purple non-finite, orange state limit)", fontsize=8)
    fig.tight_layout()
    return fig


def _near_threshold(scans: list[dict[str, Any]], cfgs: list[Config], st: AblationSettings):
    """Envelope schemes (default estimator) at the rigid envelope's first failing amplitude.

    Returns ``(case, runs)`` with ``runs = [(label, Result)]``, or ``(None, [])`` when no rigid
    configuration failed inside the searched range.
    """
    vecs = dict(st.directions)
    rigid = config_label("rigid", DEFAULT_ESTIMATOR)
    for c in st.conditions:
        for d in vecs:
            rig = next((r for r in scans if r["config"] == rigid and r["condition"] == c and r["direction"] == d), None)
            if rig is None or rig["kind"] != "bracketed":
                continue
            amp = rig["first_failure"]
            chosen = [cf for cf in cfgs if cf.label.startswith("fxtntsmc/") and cf.label.endswith("/" + DEFAULT_ESTIMATOR)
                      and "/none/" not in cf.label]
            chosen += [cf for cf in cfgs if cf.label == config_label("proactive", "omega")]
            pulse = tuple(amp * x for x in vecs[d])
            jobs = [_scenario(cf, c, st.horizon, pulse, st, log_dt=0.001) for cf in chosen]
            with stoppable_pool() as pool:
                res = list(pool.map(_run, jobs))
            return {"condition": c, "direction": d, "amplitude": amp}, list(zip([cf.label for cf in chosen], res))
    return None, []


def _band_gain_job(job: tuple[Config, str, str, tuple[float, ...], float, AblationSettings]) -> dict[str, Any]:
    cfg, condition, direction, vec, amp, st = job
    res = _run(_scenario(cfg, condition, st.horizon, tuple(amp * x for x in vec), st, log_dt=0.001))
    return {"config": cfg.label, "condition": condition, "direction": direction, "amplitude": amp,
            "status": res.status, "cause": failure_cause(res), "max_g": _summary(res, st.pulse_start).get("max_g"),
            "band_gain_ratio": band_gain_ratio(res, st.pulse_start)}


def band_gain(scans: list[dict[str, Any]], cfgs: list[Config], st: AblationSettings, progress: bool = False) -> list[dict]:
    """G/Omega inside the risk monitor's band, where the monitor acts most.

    For every (direction, condition), the proactive envelope with the ``omega`` and the default
    (``effective``) law is run at the largest amplitude the default configuration survived, logged
    at every step, and :func:`band_gain_ratio` is taken after the pulse onset.
    """
    labels = [config_label("proactive", DEFAULT_ESTIMATOR), config_label("proactive", "omega")]
    chosen = [c for c in cfgs if c.label in labels]
    jobs = []
    for d, vec in st.directions:
        for c in st.conditions:
            ref = next((r for r in scans if r["config"] == labels[0] and r["condition"] == c and r["direction"] == d),
                       None)
            if ref is None or ref["largest_survived"] is None:
                continue
            jobs += [(cf, c, d, vec, ref["largest_survived"], st) for cf in chosen]
    return _pool_map(_band_gain_job, jobs, progress, "band gain") if jobs else []


def _near_figure(case: dict[str, Any], runs: list[tuple[str, Result]], st: AblationSettings):
    from matplotlib.figure import Figure

    fig = Figure(figsize=(10, 3.8))
    ax1, ax2 = fig.subplots(1, 2, sharex=True)
    t_lo, t_hi = st.pulse_start - 0.5, st.pulse_start + st.pulse_duration + 3.0
    for label, res in runs:
        ch = res.channels
        t = ch["t"]
        sel = (t >= t_lo) & (t <= t_hi)
        xi = np.nanmax([np.abs(ch[f"e{a}"][sel]) / ch[f"rho_{a}"][sel] for a in "xyz"], axis=0)
        wid = np.nanmax([ch[f"rho_{a}"][sel] - ch[f"rho1_{a}"][sel] for a in "xyz"], axis=0)
        tag = label + ("" if res.ok else f" ({failure_cause(res)} at {res.failure['time']:.3g} s)")
        ax1.plot(t[sel], xi, lw=1, label=tag)
        ax2.plot(t[sel], np.maximum(wid, 1e-9), lw=1, label=tag)
    for ax in (ax1, ax2):
        ax.axvspan(st.pulse_start, st.pulse_start + st.pulse_duration, color="0.9")
        ax.set_xlabel("t (s)")
    ax1.axhline(1.0, color="k", lw=0.8, ls=":")
    ax1.set_ylabel("max_i |e_i| / rho_i")
    ax2.set_ylabel("max_i (rho_i - rho1_i) (m)")
    ax2.set_yscale("log")
    ax1.legend(fontsize=7)
    fig.suptitle(f"{case['direction']} pulse of {case['amplitude']:.4g} N, {case['condition']} control "
                 "(the rigid envelope's first failing amplitude)", fontsize=9)
    fig.tight_layout()
    return fig


def _rows(scans: list[dict[str, Any]], condition: str, direction: str) -> dict[str, dict[str, Any]]:
    return {r["config"]: r for r in scans if r["condition"] == condition and r["direction"] == direction}


def verdicts(scans: list[dict[str, Any]], st: AblationSettings) -> tuple[dict[str, list[str]], dict[str, Any]]:
    """Plain statements per direction comparing the envelope schemes, and a tally per direction.

    Tally per direction, each ``[better, equal, worse]`` over the (condition, estimator) cases:
    ``proactive_vs_rigid``, ``proactive_vs_reactive`` and ``none_vs_<envelope>`` (no envelope
    against each envelope scheme, same estimator law).
    """
    word = {1: "larger", 0: "equal (overlapping brackets)", -1: "SMALLER"}
    lines: dict[str, list[str]] = {}
    tally: dict[str, Any] = {}
    for d, _ in st.directions:
        tl = {k: [0, 0, 0] for k in ("proactive_vs_rigid", "proactive_vs_reactive", "none_vs_rigid",
                                     "none_vs_reactive", "none_vs_proactive")}
        out = []
        for c in st.conditions:
            rows = _rows(scans, c, d)
            for est in ESTIMATOR_KINDS:
                vals = {env: rows[config_label(env, est)] for env in ENVELOPE_KINDS if config_label(env, est) in rows}
                if est != "none" and not (set(vals) - {"none"}):
                    continue  # only the estimator-independent no-envelope row: nothing to compare
                if len(vals) < 2:
                    continue
                pairs = [("proactive", "rigid"), ("proactive", "reactive")] + [("none", e) for e in ENVELOPE_KINDS[1:]]
                said = []
                for x, y in pairs:
                    if x in vals and y in vals:
                        v = compare(vals[x], vals[y])
                        tl[f"{x}_vs_{y}"][1 - v] += 1
                        said.append(f"{'no envelope' if x == 'none' else x} vs {y} {word[v]}")
                parts = ", ".join(f"{env} {survival_text(r)} N ({r['cause'] or 'no failure'}"
                                  + ("" if r["monotone"] else f"; survives again: {intervals_text(r)}") + ")"
                                  for env, r in vals.items())
                out.append(f"{c} control, estimator `{est}`: " + "; ".join(said) + f". Survival: {parts}.")
            ft = rows.get("ftsmc")
            if ft is not None:
                out.append(f"{c} control, FTSMC: {survival_text(ft)} N ({ft['cause'] or 'no failure'}"
                           + ("" if ft["monotone"] else f"; survival intervals {intervals_text(ft)}") + ").")
        lines[d], tally[d] = out, tl
    return lines, tally


def run(out: Path, *, quick: bool = False, progress: bool = False, settings: AblationSettings | None = None,
        pulse: str | Sequence[float] | None = None, pulse_start: float | None = None) -> Path:
    """Run the ablation study and write ``report.md``, ``results.json`` and figures to ``out``.

    Parameters
    ----------
    out : pathlib.Path
        Output folder (created).
    quick : bool, optional
        CI-sized run (:meth:`AblationSettings.quick`).
    progress : bool, optional
        Show progress bars.
    settings : AblationSettings, optional
        Override the study's settings (tests, experiments); ``quick``, ``pulse`` and
        ``pulse_start`` are then ignored.
    pulse : str or sequence of float, optional
        ``--pulse F1,F2,F3,F4,F5``: one pulse direction (scaled by the amplitude) instead of the
        default ones.
    pulse_start : float, optional
        ``--pulse-start T``: pulse onset (s); the run lasts until T + 20 s.

    Returns
    -------
    pathlib.Path
        Path of ``report.md``.
    """
    st = settings or settings_for(quick, pulse, pulse_start)
    out = Path(out)
    cfgs = [c for c in configurations() if not st.configs or c.label in st.configs]
    compile_first([(k, "5dof") for k in kinds_in(o for c in cfgs for o in c.overrides)], progress=progress)
    nominal = _pool_map(_nominal_job, [(c, cond, st) for cond in st.conditions for c in cfgs], progress, "nominal")
    jobs = [(c, cond, d, vec, st) for d, vec in st.directions for cond in st.conditions for c in cfgs]
    scans = _pool_map(_scan_job, jobs, progress, "survival scan")
    reference = _pool_map(_reference_job, jobs, progress, "reference")

    rep = Report(out, "Ablation: envelope x estimator x controller under a growing pulse")
    rep.paragraph(
        "Question: does the paper's proactive risk monitor (flexible envelope, Sec. 3.2) prevent failure "
        "under a large disturbance better than a rigid envelope, a reactive one, or none, and how do the "
        "estimator laws and the FTSMC baseline compare?  Section 4 scenario (ERRATA corrections, seed 0, "
        f"nonsingular surface, start widened to xi0 = 0.9), {len(cfgs)} configurations.")
    rep.heading("Method")
    ratio = 10 ** (1 / st.per_decade)
    rep.bullets([
        f"Pulse: constant body-frame force/moment `A x direction`, on for {st.pulse_start:g} <= t < "
        f"{st.pulse_start + st.pulse_duration:g} s, added to the Section 4 disturbance; run to t = {st.horizon:g} s.",
        "Directions (reported separately): " + ", ".join(f"{d} = {list(v)}" for d, v in st.directions)
        + " (F_u, F_v, F_w in N, M_q, M_r in N m per newton of A). Sway and heave are unactuated: sway is fought "
          "through yaw, heave excites the pitch internal dynamics.",
        "Conditions: " + ", ".join(f"`{c}`" + (f" ({' '.join(CONDITIONS[c])})" if CONDITIONS[c] else
                                                " (controller at every RK4 stage, as in the paper)")
                                   for c in st.conditions) + ".",
        f"Survival = the run reaches t = {st.horizon:g} s with no failure (envelope violation, pitch limit "
        "(sim.theta_limit), non-finite state, state limit).",
        f"Survival scan: a geometric grid of A from {st.a_min:g} N to {st.a_max:g} N with {st.per_decade} points per "
        f"decade (ratio {ratio:.3g}), then geometric bisection of every grid cell whose ends differ until "
        f"hi/lo - 1 <= {st.rtol:g}.  Survival is not assumed monotone: every survival interval is reported; a window "
        f"narrower than one grid step can be missed.  `first failure` = smallest failing A found, `survives up to` = "
        "largest A below it that survived (every probe up to it survived).",
        f"Reference amplitude for the metric tables: {st.a_ref:g} N; metrics over t >= pulse onset.",
        "Actuators are ideal (no saturation) in every condition, as in the paper.  Without an envelope "
        "Omega = G = 1, so the `printed`, `omega` and `effective` adaptive laws are the same law there (one "
        f"configuration, `{config_label('none', DEFAULT_ESTIMATOR)}`).",
    ])
    if quick:  # a smoke test of the study's machinery: what it saw, not what it found
        rep.heading(f"Observations of this quick run ({len(cfgs)} configurations, coarse grid): not findings")
    else:
        rep.heading("Findings")
    lines, tally = verdicts(scans, st)
    for d, _ in st.directions:
        rep.heading(f"{d} pulse", 3)
        tl = tally[d]
        said = [f"{k.replace('_vs_', ' vs ').replace('none', 'no envelope')} {'/'.join(map(str, v))} of {sum(v)}"
                for k, v in tl.items() if sum(v)]
        if said:
            rep.paragraph("Larger / equal / smaller first transition over the (condition, estimator) cases: "
                          + "; ".join(said) + " (compared on the first transition: `survives up to` of one "
                          "against `first failure` of the other).")
        nm = [r for r in scans if r["direction"] == d and not r["monotone"]]
        if nm:
            rep.paragraph("Not monotone (fails, then survives a larger pulse): " + "; ".join(
                f"{r['config']} {r['condition']}: first failure {fmt(r['first_failure'])} N ({r['cause']}), "
                f"survives {intervals_text(r)}" for r in nm) + ".")
        rep.bullets(lines[d] or ["(no complete envelope comparison in this configuration)"])
    n_fail_nom = [r for r in nominal if r["status"] != "ok"]
    rep.paragraph(
        "Without any pulse: " + ("every configuration completes Section 4." if not n_fail_nom else
                                 "; ".join(f"{r['config']} ({r['condition']}) fails at t = {fmt(r['fail_time'])} s: "
                                           f"{r['cause']}" for r in n_fail_nom) + "."))
    pro = [r for r in reference if r["config"].startswith("fxtntsmc/proactive")]
    acts = [r for r in pro if r.get("max_g") is not None and r["max_g"] > 0]
    rep.paragraph(
        f"Risk monitor at the reference amplitude: the trigger g = gamma(hbar) became positive in "
        f"{len(acts)} of {len(pro)} proactive runs"
        + (": " + ", ".join(f"{r['config']} {r['direction']}/{r['condition']} (max g {fmt(r['max_g'], 2)}, widening "
                           f"{fmt(r.get('max_widening'), 3)} m)" for r in acts) if acts else "") + ".")
    rep.heading("Survival per configuration (amplitude A in N)")
    rows = [[r["config"], r["condition"], r["direction"], fmt(r["survives_up_to"]), fmt(r["first_failure"]),
             r["cause"] or "no failure", r["fail_time"], pitch_at(r, r["survives_up_to"]), intervals_text(r),
             "yes" if r["monotone"] else "NO", len(r["probes"])] for r in scans]
    rep.table(["configuration", "condition", "direction", "survives up to", "first failure", "cause",
               "failure time (s)", "max pitch at 'survives up to' (deg)", "survival intervals", "monotone", "runs"],
              rows)
    rep.figure(_figure(scans, st), "survival",
               "Survival intervals per configuration and direction (green), failing probes as ticks coloured by cause.")
    case, near = _near_threshold(scans, cfgs, st)
    near_info = None
    if case is not None:
        near_info = {**case, "runs": {lab: {"status": r.status, "cause": failure_cause(r),
                                            "fail_time": (r.failure or {}).get("time"),
                                            "band_gain_ratio": band_gain_ratio(r, st.pulse_start)}
                                      for lab, r in near}}
        rep.heading("At the rigid envelope's first failing amplitude")
        rep.paragraph("Normalised error max_i |e_i|/rho_i (failure at 1) and envelope widening rho - rho1 for the "
                      f"envelope schemes with the `{DEFAULT_ESTIMATOR}` estimator (and the proactive one with `omega`): "
                      + "; ".join(f"{lab}: {r.status}" + (f" ({failure_cause(r)} at t = {r.failure['time']:.4g} s)"
                                                           if r.failure else "") for lab, r in near) + ".")
        ratios = [(lab, v["band_gain_ratio"]) for lab, v in near_info["runs"].items() if v["band_gain_ratio"]]
        if ratios:
            rep.paragraph("Effective gain inside the risk monitor's band (0 < g < 1), G/Omega = 1/(1 - 2 c xi^2/rho) "
                          "(docs/derivation.md section 5): " + "; ".join(
                              f"{lab}: {q['samples']} samples, min {fmt(q['min'], 3)}, median {fmt(q['median'], 3)}, "
                              f"max {fmt(q['max'], 3)}" for lab, q in ratios)
                          + ".  The `omega` law adapts Omega/G times faster than the Lyapunov-consistent `effective` "
                            "law there.")
        rep.figure(_near_figure(case, near, st), "near_threshold",
                   "What each envelope scheme does at the pulse that breaks the rigid envelope.")
    bands = band_gain(scans, cfgs, st, progress)
    if bands:
        rep.heading("Effective gain inside the risk monitor's band")
        rep.paragraph("G/Omega = 1/(1 - 2 c xi^2/rho) (docs/derivation.md section 5) over the samples with 0 < g < 1 "
                      "after the pulse onset, for the proactive envelope at the largest amplitude the default "
                      "configuration survived, logged at every step.  The `omega` law adapts Omega/G times faster "
                      "than the Lyapunov-consistent `effective` law there.")
        rep.table(["configuration", "condition", "direction", "A (N)", "status", "max g", "band samples",
                   "G/Omega min", "median", "max"],
                  [[b["config"], b["condition"], b["direction"], b["amplitude"], b["status"], b["max_g"],
                    *((b["band_gain_ratio"][k] for k in ("samples", "min", "median", "max")) if b["band_gain_ratio"]
                      else (0, None, None, None))] for b in bands])
    rep.heading(f"Metrics at the reference amplitude ({st.a_ref:g} N), t >= {st.pulse_start:g} s")
    keys = ("status", "cause", "fail_time", "max_abs_e", "rmse", "max_abs_tau", "energy_tau", "tv_tau", "max_g",
            "max_widening")
    rep.table(["configuration", "condition", "direction", *keys],
              [[r["config"], r["condition"], r["direction"], *[r.get(k) for k in keys]] for r in reference])
    rep.paragraph("max_abs_e: largest |e_i| over the axes (m); max_abs_tau: largest |tau_j| (N or N m); "
                  "energy_tau: sum over inputs of the integral of tau^2; tv_tau: total variation of tau per second, "
                  "summed over inputs; max_g: largest risk trigger; max_widening: largest rho - rho1 (m).")
    rep.heading(f"Section 4 without pulse ({st.nominal_duration:g} s)")
    rep.table(["configuration", "condition", *NOMINAL_KEYS],
              [[r["config"], r["condition"], *[r.get(k) for k in NOMINAL_KEYS]] for r in nominal])
    rep.paragraph("settle_*: time after which every axis stays within 1 cm / 1 mm (inf: not settled).  "
                  "Every probe of the survival scans (amplitude, outcome, cause, time) is in `results.json`.")
    write_json(out / "results.json", {"study": "ablation", "settings": {**asdict(st), "horizon": st.horizon},
                                      "tally": tally, "near_threshold": near_info, "band_gain": bands,
                                      "nominal": nominal,
                                      "scans": scans, "reference": reference})
    return rep.write()


STUDY = StudySpec("ablation", run, "envelope x estimator x controller: survival of a growing pulse (grid scan, "
                                   "bisection of every transition), failures by cause, metrics at a reference "
                                   "amplitude", options=("pulse", "pulse_start"))
