"""``auvtrack reproduce``: the paper's Section 4, both controllers, Figures 3-8, verdicts.

Runs the packaged Section 4 scenario with the FXTNTSMC and with the FTSMC baseline, writes a
run folder for each, the paper's Figures 3-8 (PNG and PDF), a metrics table (Markdown and
JSON) and a verdict on each of the paper's three claims computed from the measured numbers;
``summary.md`` and the self-contained ``report.html`` hold the same report
(:class:`~auvtrack.report.Report`).

Every verdict states its conditions (estimator law, sliding surface, start treatment, envelope
baseline, gains; :func:`conditions`).  Besides the corrected defaults the claims are judged for
each of the paper's printed forms (:data:`FORMS`): the adaptive law (34), the surface (28), both,
the baseline (24) and the untreated start, which are reported as not testable where the
FXTNTSMC cannot complete the run.
"""
from __future__ import annotations

import json
import math
import multiprocessing
import signal
import warnings
from dataclasses import dataclass
from pathlib import Path

from tqdm.auto import tqdm

from ..batch.runner import default_workers, stoppable_pool
from ..control.fxtntsmc import StartOutsideEnvelope
from ..control.gain_presets import get_gain_preset
from ..simulation import plotting
from ..simulation.compiling import compile_first
from ..simulation.pipeline import prepare, run_prepared
from ..simulation.result import Result
from ..scenario import load_scenario
from ..scenario import paper_scenario_path
from ..report import Report, metric_unit
from ..report_figures import make_readable

CONTROLLERS = (("FXTNTSMC", "fxtntsmc"), ("FTSMC", "ftsmc"))
# the same comparison with both controllers tuned by one procedure (docs/tuning.md)
TUNED_PRESETS = {"fxtntsmc": "fxtntsmc_tuned", "ftsmc": "ftsmc_tuned"}
AXES = ("x", "y", "z")
INPUTS = ("u", "q", "r")
FIGURE_DPI = 200
"""Resolution of the paper figures' PNG files (their PDFs are vector)."""
FIGURES = (
    ("fig3_trajectory3d", plotting.fig_trajectory3d),
    ("fig4_positions", plotting.fig_positions),
    ("fig5_velocities", plotting.fig_velocities),
    ("fig6_inputs", plotting.fig_inputs),
    ("fig7_errors", plotting.fig_errors),
    ("fig8_chi", plotting.fig_chi),
)
CAPTIONS = {
    "fig3_trajectory3d": "Fig. 3: path of the virtual point η₁ (the point the controllers track, vehicle.l = {ell} ahead "
                         "of the centre of gravity) against the reference η_d (dashed); the thin lines are the centres "
                         "of gravity, which trail the virtual point by design. Hollow markers: each run's start. The "
                         "z axis points down (NED).",
    "fig4_positions": "Fig. 4: virtual-point position η₁ against the reference η_d (dashed) per axis; thin lines: "
                      "centre of gravity, vehicle.l = {ell} behind it along the body axis (not a tracking error).",
    "fig5_velocities": "Fig. 5: body velocities u, v, w and rates q, r.",
    "fig6_inputs": "Fig. 6: control inputs; left the whole run (its scale is set by the start-up spikes), right the "
                   "steady state t ≥ {t_ss:g} s on its own scale, where the chattering claim is judged (the window "
                   "of the steady-state metrics); the smoother line is drawn on top.",
    "fig7_errors": "Fig. 7: position errors e = η₁ − η_d. Left: with the envelope ±ρ (dash-dot) and the baseline ±ρ₁ "
                   "(dashed), linear as in the paper; right: |e| and the envelopes on a log scale, where the final "
                   "envelope stays visible. Bottom: |e_i|/ρ_i (a run fails where it reaches 1) and the flexible part "
                   "ρ̄ = ρ − ρ₁ of the envelope. The FTSMC has no envelope.",
    "fig8_chi": "Fig. 8: approximation error χ − χ̂ of the RBF network (FXTNTSMC only; the FTSMC has no estimator).",
}


FORMS = (
    ("corrected", "corrected forms (the defaults)", ()),
    ("omega", "Omega-weighted adaptive law (ERRATA 14)", ("estimator.kind=omega",)),
    ("printed_law34", "adaptive law (34) as printed", ("estimator.kind=printed",)),
    ("printed_surface28", "surface (28) as printed", ("controller.surface=printed",)),
    ("printed_law34_surface28", "law (34) and surface (28) as printed",
     ("estimator.kind=printed", "controller.surface=printed")),
    ("printed_baseline24", "envelope baseline (24) as printed", ("envelope.baseline=printed",)),
    ("printed_start", "Section 4's start without treatment", ("envelope.widen_start=false",)),
)
"""Forms of the FXTNTSMC whose verdicts ``reproduce`` reports: (name, label, overrides)."""
CLAIMS = ("faster convergence", "higher accuracy", "less chattering")


@dataclass
class Verdict:
    """One claim of the paper, tested on measured numbers."""

    claim: str
    verdict: str  # "supported", "not supported", "mixed" or "not testable"
    evidence: str
    conditions: str = ""


def conditions(scenario, gains: str = "paper (Section 4)", notes: tuple[str, ...] = ()) -> dict[str, str]:
    """The conditions a FXTNTSMC verdict holds under, read from its scenario.

    Returns
    -------
    dict
        ``estimator``, ``surface``, ``start``, ``baseline`` and ``gains`` as short text.
    """
    env, ctl = scenario.envelope, scenario.controller
    widened = [n for n in notes if "widened" in n]
    if not env.widen_start:
        start = "as printed (no treatment)"
    elif widened:
        start = f"widened to |e|/rho = xi0 = {env.xi0:g} (ERRATA 9)"
    else:
        start = "inside the envelope (no treatment needed)"
    return {
        "estimator": {"effective": "effective-gain law (G = Omega - c1, Lyapunov-consistent)",
                      "omega": "Omega-weighted law (ERRATA 14)", "printed": "law (34) as printed",
                      "none": "no estimator"}[scenario.estimator.kind],
        "surface": ("nonsingular (C1 switch on |z|)" if ctl.surface == "nonsingular"
                    else f"(28) as printed, |z| floored at {ctl.z_floor:g}"),
        "start": start,
        "baseline": "corrected (24)" if env.baseline == "corrected" else "(24) as printed",
        "gains": gains,
    }


def conditions_text(c: dict[str, str]) -> str:
    """One line: ``estimator ...; surface ...; start ...; baseline ...; gains ...``."""
    return "; ".join(f"{k} {v}" for k, v in c.items())


def _run(kind: str, overrides: list[str], window: tuple[float, float]) -> tuple[Result, Result]:
    """Full-window run (kept) and the same run with the steady-state metrics window.

    The compiled kernel releases the GIL, so the two runs share the machine's cores.
    """
    base = [f"controller.kind={kind}", *overrides]
    preps = [prepare(load_scenario(paper_scenario_path(), base)),
             prepare(load_scenario(paper_scenario_path(), base + [f"metrics.window=[{window[0]}, {window[1]}]"]))]
    with stoppable_pool() as pool:
        full, steady = pool.map(run_prepared, preps)
    return full, steady


def preset_overrides(name: str) -> list[str]:
    """Overrides setting every gain of gain preset ``name`` explicitly.

    ``controller.preset`` alone would lose to the gains that ``scenarios/paper.toml`` writes
    out (keys written next to a preset win), so the comparison sets each one.
    """
    return [f"controller.{k}={v!r}" for k, v in get_gain_preset(name).gains.items()]


def _figure_worker() -> None:
    """A figure process leaves Ctrl-C to its parent (which terminates it) and ends quietly on SIGTERM."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)


def _render(job: tuple[str, list, Path, dict]) -> tuple[str, float]:
    """Draw and save one figure (runs in a worker process); return its name and its smallest text's shown size (px)."""
    name, pairs, fig_dir, kw = job
    fn = dict(FIGURES)[name]
    fig = fn(pairs, **kw)
    text_px = make_readable(fig, FIGURE_DPI)
    plotting.save_figure(fig, fig_dir / name, dpi=FIGURE_DPI)
    return name, text_px


def _compare(claim: str, metric: str, names, a: dict, b: dict, unit: str) -> Verdict:
    wins = [a[f"{metric}_{n}"] < b[f"{metric}_{n}"] for n in names]
    rows = ", ".join(f"{n}: {_fmt(a[f'{metric}_{n}'])} vs {_fmt(b[f'{metric}_{n}'])} {unit}" for n in names)
    verdict = "supported" if all(wins) else ("not supported" if not any(wins) else "mixed")
    return Verdict(claim, verdict, f"{metric} FXTNTSMC vs FTSMC — {rows}")


def _fmt(x) -> str:
    return "inf" if x is None or (isinstance(x, float) and not math.isfinite(x)) else f"{x:.4g}"


def verdicts(full: dict[str, dict], steady: dict[str, dict], window: tuple[float, float],
             cond: str = "") -> list[Verdict]:
    """The paper's three claims judged on the measured metrics (lower is better throughout).

    ``cond`` (:func:`conditions_text`) is attached to every verdict.
    """
    a, b = full["FXTNTSMC"], full["FTSMC"]
    sa, sb = steady["FXTNTSMC"], steady["FTSMC"]
    vs = [
        _compare("faster convergence (time for |e| to stay below 1 cm)", "settle_1cm", AXES, a, b, "s"),
        _compare(f"higher accuracy (steady-state RMSE, t in [{window[0]:g}, {window[1]:g}] s)", "rmse", AXES, sa, sb, "m"),
        _compare(f"less chattering (total variation of tau per second, t in [{window[0]:g}, {window[1]:g}] s)",
                 "tv_tau", INPUTS, sa, sb, "N/s or N m/s"),
    ]
    for v in vs:
        v.conditions = cond
    return vs


def _not_testable(why: str, cond: str) -> list[Verdict]:
    return [Verdict(c, "not testable", why, cond) for c in CLAIMS]


def form_verdicts(overrides: list[str], ftsmc: tuple[dict, dict], window: tuple[float, float],
                  done: dict[str, tuple[Result, Result]] | None = None) -> list[dict]:
    """Verdicts for every form of :data:`FORMS` against the FTSMC run ``ftsmc`` = (full, steady) metrics.

    ``done`` maps a form's name to its (full, steady) runs when they were made already (the
    corrected form is ``reproduce``'s main FXTNTSMC run); the others are run here.

    Returns
    -------
    list of dict
        Per form: ``name``, ``label``, ``overrides``, ``conditions``, ``status``, ``failure``,
        ``verdicts`` and the FXTNTSMC's ``full_window`` / ``steady_window`` metrics.
    """
    out = []
    for name, label, extra in FORMS:
        ov = [*overrides, *extra]
        sc = load_scenario(paper_scenario_path(), ["controller.kind=fxtntsmc", *ov])
        rec = {"name": name, "label": label, "overrides": list(extra), "failure": None,
               "full_window": None, "steady_window": None}
        try:
            with warnings.catch_warnings():  # the start widening is stated in the conditions
                warnings.simplefilter("ignore")
                full, steady = (done or {}).get(name) or _run("fxtntsmc", ov, window)
        except StartOutsideEnvelope as e:
            cond = conditions(sc)
            rec.update(conditions=cond, status="refused", failure={"cause": "start_refused", "detail": str(e)},
                       verdicts=[v.__dict__ for v in _not_testable(f"the run is refused: {e}", conditions_text(cond))])
            out.append(rec)
            continue
        cond = conditions(sc, notes=tuple(full.meta.get("notes", ())))
        rec.update(conditions=cond, status=full.status, failure=full.failure,
                   full_window=_jsonable({"m": full.metrics})["m"], steady_window=_jsonable({"m": steady.metrics})["m"])
        if full.ok:
            vs = verdicts({"FXTNTSMC": full.metrics, "FTSMC": ftsmc[0]}, {"FXTNTSMC": steady.metrics, "FTSMC": ftsmc[1]},
                          window, conditions_text(cond))
        else:
            f = full.failure
            vs = _not_testable(f"the FXTNTSMC run fails at t = {f['time']:.4g} s ({f['cause']}: {f['detail']})",
                               conditions_text(cond))
        rec["verdicts"] = [v.__dict__ for v in vs]
        out.append(rec)
    return out


def _forms_report(rep: Report, forms: list[dict]) -> None:
    """The verdicts for each form of the law (:data:`FORMS`), with conditions and evidence."""
    rep.heading("The claims under each form of the FXTNTSMC")
    rep.paragraph("The FTSMC run is the same throughout (default gains); each row changes the FXTNTSMC only as named.")
    rep.table(["form", "status", *CLAIMS], [[f["label"], f["status"], *(v["verdict"] for v in f["verdicts"])]
                                            for f in forms])
    for f in forms:
        rep.paragraph(f"**{f['label']}** ({conditions_text(f['conditions'])}): status **{f['status']}**")
        rep.verdicts([(v["claim"], v["verdict"], v["evidence"]) for v in f["verdicts"]])


def _table_rows(full: dict[str, dict], steady: dict[str, dict], window: tuple[float, float]) -> list[list[str]]:
    keys = ([f"settle_{s}_{a}" for s in ("5cm", "1cm", "1mm") for a in AXES]
            + [f"rmse_{a}" for a in AXES] + [f"max_abs_{a}" for a in AXES] + [f"itae_{a}" for a in AXES]
            + [f"max_abs_tau_{j}" for j in INPUTS] + [f"energy_tau_{j}" for j in INPUTS] + [f"tv_tau_{j}" for j in INPUTS]
            + [f"t_sat_tau_{j}" for j in INPUTS])  # time with the input's command saturated
    rows = [[k, metric_unit(k), "whole run", _fmt(full["FXTNTSMC"][k]), _fmt(full["FTSMC"][k])] for k in keys]
    for k in [f"rmse_{a}" for a in AXES] + [f"max_abs_{a}" for a in AXES] + [f"tv_tau_{j}" for j in INPUTS]:
        rows.append([k, metric_unit(k), f"[{window[0]:g}, {window[1]:g}] s", _fmt(steady["FXTNTSMC"][k]),
                     _fmt(steady["FTSMC"][k])])
    return rows


def reproduce(out: Path, *, quick: bool = False, progress: bool = False) -> str:
    """Run Section 4 for both controllers and write runs, figures, tables and verdicts to ``out``.

    Parameters
    ----------
    out : pathlib.Path
        Output folder (created).
    quick : bool, optional
        Simulate 20 s instead of 100 s (a smoke test; verdicts then use the window [10, 20] s).
    progress : bool, optional
        Show a progress bar.

    Returns
    -------
    str
        The Markdown summary written to ``out/summary.md`` (which also ends with the scenarios
        and the version); ``out/report.html`` holds the same report as one self-contained page,
        figures embedded.
    """
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    overrides = ["sim.duration=20"] if quick else []
    window = (10.0, 20.0) if quick else (50.0, 100.0)  # steady state: accuracy and chattering claims
    compile_first([(kind, "5dof") for _, kind in CONTROLLERS], progress=progress)
    bar = tqdm(total=2 * len(CONTROLLERS) + len(FIGURES), disable=not progress, desc="reproduce", unit="step")
    try:  # a stop (Ctrl-C, SIGTERM) closes the bar first: the one-line message starts a line
        runs, full, steady, steady_runs = {}, {}, {}, {}
        tuned, tuned_full, tuned_steady = {}, {}, {}
        for label, kind in CONTROLLERS:
            bar.set_postfix_str(kind)
            res, res_ss = _run(kind, overrides, window)
            res.save(out / kind, mat=True)
            runs[label], full[label], steady[label] = res, res.metrics, res_ss.metrics
            steady_runs[label] = res_ss
            bar.update()
            bar.set_postfix_str(TUNED_PRESETS[kind])
            res, res_ss = _run(kind, [*overrides, *preset_overrides(TUNED_PRESETS[kind])], window)
            res.save(out / "tuned" / kind)
            tuned[label], tuned_full[label], tuned_steady[label] = res, res.metrics, res_ss.metrics
            bar.update()
        pairs = list(runs.items())
        kw = {"fig6_inputs": {"steady_from": window[0]}}
        jobs = [(name, pairs, out / "figures", kw.get(name, {})) for name, _ in FIGURES]
        text_px = {}
        # figures are independent: one process per core; leaving the block (done, or a stop) terminates them
        with multiprocessing.Pool(default_workers(), initializer=_figure_worker) as pool:
            for name, text_px[name] in pool.imap(_render, jobs):
                bar.set_postfix_str(name)
                bar.update()
    finally:
        bar.close()
    sc_default = load_scenario(paper_scenario_path(), ["controller.kind=fxtntsmc", *overrides])
    cond = conditions(sc_default, notes=tuple(runs["FXTNTSMC"].meta.get("notes", ())))
    cond_tuned = conditions(sc_default, gains=f"tuned presets {', '.join(TUNED_PRESETS.values())}",
                            notes=tuple(tuned["FXTNTSMC"].meta.get("notes", ())))
    vs = verdicts(full, steady, window, conditions_text(cond))
    vs_tuned = verdicts(tuned_full, tuned_steady, window, conditions_text(cond_tuned))
    forms = form_verdicts(overrides, (full["FTSMC"], steady["FTSMC"]), window,
                          done={"corrected": (runs["FXTNTSMC"], steady_runs["FXTNTSMC"])})
    rep = _report(out, runs, full, steady, vs, window)
    _tuned_report(rep, tuned, vs_tuned)
    _forms_report(rep, forms)
    _figures(rep, runs, window, text_px)
    for label, r in runs.items():
        rep.scenario(_shown_scenario(r), f"Scenario of the {label} run (resolved; run folder `{r.scenario['controller']['kind']}/`)")
    rep.write("summary.md", html="report.html")
    (out / "metrics.json").write_text(json.dumps(
        {"full_window": _jsonable(full), "steady_window": {"window": list(window), **_jsonable(steady)},
         "status": {k: r.status for k, r in runs.items()},
         "conditions": cond, "verdicts": [v.__dict__ for v in vs],
         "tuned": {"presets": TUNED_PRESETS, "full_window": _jsonable(tuned_full),
                   "steady_window": {"window": list(window), **_jsonable(tuned_steady)},
                   "status": {k: r.status for k, r in tuned.items()},
                   "conditions": cond_tuned, "verdicts": [v.__dict__ for v in vs_tuned]},
         "forms": forms}, indent=2))
    return rep.text(closing=False)


def _jsonable(d: dict) -> dict:
    return {k: {m: (None if isinstance(v, float) and not math.isfinite(v) else v) for m, v in vals.items()}
            for k, vals in d.items()}


def _shown_scenario(res: Result) -> dict:
    """The resolved scenario of a run without the controller's drawn internals (RBF centres...)."""
    return {k: v for k, v in res.scenario.items() if k != "resolved"}


def _status_lines(runs: dict[str, Result], suffix: str = "") -> list[str]:
    lines = []
    for label, r in runs.items():
        line = f"{label}{suffix}: status **{r.status}**"
        if r.failure:
            line += f" (t = {r.failure['time']:.4g} s, {r.failure['cause']}: {r.failure['detail']})"
        lines.append(line)
    return lines


def _tuned_report(rep: Report, runs: dict[str, Result], vs: list[Verdict]) -> None:
    """The claims again, with both controllers tuned by the same procedure (docs/tuning.md)."""
    rep.heading("The same claims under fair tuning")
    rep.paragraph("Both controllers with the gains of one optimiser, budget and objective "
                  f"(gain presets {', '.join(f'`{p}`' for p in TUNED_PRESETS.values())}; docs/tuning.md). "
                  "Run folders: `tuned/`.")
    rep.bullets(_status_lines(runs, " (tuned)"))
    rep.paragraph(f"Conditions of the FXTNTSMC: {vs[0].conditions if vs else ''}.")
    rep.verdicts([(v.claim, v.verdict, v.evidence) for v in vs])


def _report(out: Path, runs, full, steady, vs, window) -> Report:
    rep = Report(out, "Section 4 reproduction")
    notes = [f"note ({label}): {note}" for label, r in runs.items() for note in r.meta.get("notes", [])]
    rep.bullets(_status_lines(runs) + notes)
    rep.heading("The paper's claims")
    rep.paragraph(f"Conditions of the FXTNTSMC: {vs[0].conditions if vs else ''}. The FTSMC: default gains. "
                  "Other forms of the law: the section on each form below.")
    rep.verdicts([(v.claim, v.verdict, v.evidence) for v in vs])
    rep.heading("Metrics")
    rep.table(["metric (docs/metrics.md)", "unit", "window", "FXTNTSMC", "FTSMC"], _table_rows(full, steady, window))
    return rep


def _figures(rep: Report, runs: dict[str, Result], window: tuple[float, float], text_px: dict[str, float]) -> None:
    rep.heading("Figures")
    rep.paragraph("Files: `figures/fig3_trajectory3d` … `figures/fig8_chi` (PNG and PDF).")
    ell = plotting.lever_arm(next(iter(runs.values())))
    for name, _ in FIGURES:
        rep.image(rep.out / "figures" / f"{name}.png",
                  CAPTIONS[name].format(ell="?" if ell is None else f"{ell:g} m", t_ss=window[0]), text_px[name])
