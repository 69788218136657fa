"""Report of ``auvtrack compare``: figures, ``report.md`` / ``report.html`` and ``results.json``.

Built with the shared :class:`auvtrack.report.Report`.  Figures (Matplotlib ``Figure``,
no pyplot): the leaderboard, failure rates with their Wilson intervals, metric distributions per
tier and representative trajectories.  ``results.json`` holds every number of the report; its
``timing`` entry is the only part that differs between two runs of the same comparison.
"""
from __future__ import annotations

import platform
import time
from pathlib import Path
from typing import Any, Mapping, Sequence

import numpy as np

from .leaderboard import metric_info
from .report_aggregates import write_aggregates_section
from .report_competitors import TUNING_COLUMNS, failure_cause_rows, gain_rows, not_tuned_on, tuning_rows
from ..report import Report, fmt, write_json
from .suite import ControllerEntry, Suite

__all__ = ["write_report", "figure_leaderboard", "figure_failures", "figure_distribution", "figure_trajectories"]


def _colors(names: Sequence[str]) -> dict[str, Any]:
    from matplotlib import colormaps

    cmap = colormaps["tab10"]
    return {n: cmap(i % 10) for i, n in enumerate(names)}


def _ci(lo: float, hi: float, digits: int = 3) -> str:
    return f"[{fmt(lo, digits)}, {fmt(hi, digits)}]"


def _pct(x: float) -> str:
    return f"{100.0 * x:.1f} %"


def _pct_ci(lo: float, hi: float) -> str:
    """A rate's interval in percent, as the rate beside it."""
    return f"[{100.0 * lo:.1f}, {100.0 * hi:.1f}] %"


def _header(metric: str) -> str:
    """A metric's column head with its unit and interval."""
    unit = metric_info(metric)[1]
    return f"{metric} ({unit}) median [95 % bootstrap]" if unit and unit != "-" else f"{metric} median [95 % bootstrap]"


def figure_leaderboard(analysis: Mapping, tiers: Sequence[str]):
    """Overall score (bars), tier scores (markers) and the bootstrap interval of the overall rank."""
    from matplotlib.figure import Figure

    order = analysis["scores"]["order"]
    overall, tier_scores = analysis["scores"]["overall"], analysis["scores"]["tiers"]
    ranks = analysis["rank_intervals"]
    n = len(order)
    fig = Figure(figsize=(10, 0.5 * n + 1.8))
    ax, ax2 = fig.subplots(1, 2, gridspec_kw={"width_ratios": [2, 1]})
    y = np.arange(n)[::-1]
    ax.barh(y, [overall[c]["score"] for c in order], color="0.8", label="overall score")
    markers = "osD^vP*X"
    for j, t in enumerate(tiers):
        ax.plot([tier_scores[t][c]["score"] for c in order], y, markers[j % len(markers)], label=t, alpha=0.8)
    ax.set_yticks(y, order)
    ax.set_xlabel("score (mean weighted rank; lower is better)")
    ax.set_xlim(0.8, n + 0.2)
    ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.18), ncol=len(tiers) + 1)
    ax.grid(axis="x", alpha=0.3)
    for yi, c in zip(y, order):
        lo, hi = ranks[c]["low"], ranks[c]["high"]
        ax2.plot([lo, hi], [yi, yi], "k-", lw=2)
        ax2.plot(overall[c]["rank"], yi, "ko")
    ax2.set_yticks(y, [""] * n)
    ax2.set_xlim(0.5, n + 0.5)
    ax2.set_xticks(range(1, n + 1))
    ax2.set_xlabel("overall rank, 95 % bootstrap interval")
    ax2.grid(axis="x", alpha=0.3)
    fig.tight_layout()
    return fig


def figure_failures(analysis: Mapping, tiers: Sequence[str], controllers: Sequence[str]):
    """Failure rate per tier and controller (pooled over tasks) with Wilson intervals."""
    from matplotlib.figure import Figure

    rec = {(r["tier"], r["controller"]): r for r in analysis["pooled_tier"]}
    colors = _colors(controllers)
    fig = Figure(figsize=(max(6.0, 1.4 * len(tiers) + 2), 3.6))
    ax = fig.subplots()
    w = 0.8 / max(1, len(controllers))
    for j, c in enumerate(controllers):
        xs = np.arange(len(tiers)) + (j - (len(controllers) - 1) / 2) * w
        p = np.array([rec[(t, c)]["failure_rate"] for t in tiers])
        lo = np.array([rec[(t, c)]["failure_ci"][0] for t in tiers])
        hi = np.array([rec[(t, c)]["failure_ci"][1] for t in tiers])
        ax.bar(xs, p, w, color=colors[c], label=c)
        ax.errorbar(xs, p, yerr=[p - lo, hi - p], fmt="none", ecolor="k", elinewidth=1, capsize=2)
    ax.set_xticks(np.arange(len(tiers)), tiers)
    ax.set_ylim(0, 1.02)
    ax.set_ylabel("failure rate (Wilson 95 %)")
    ax.legend(fontsize=7, ncol=min(4, len(controllers)))
    ax.grid(axis="y", alpha=0.3)
    fig.tight_layout()
    return fig


def figure_distribution(df, metric: str, tiers: Sequence[str], controllers: Sequence[str]):
    """Box plots of a metric per controller, one panel per tier (completed runs; failures counted)."""
    from matplotlib.figure import Figure

    colors = _colors(controllers)
    fig = Figure(figsize=(2.6 * len(tiers) + 1, 3.4))
    axes = np.atleast_1d(fig.subplots(1, len(tiers), sharey=True))
    desc, unit = metric_info(metric)
    for ax, t in zip(axes, tiers):
        g = df[df["tier"] == t]
        data, labels = [], []
        for c in controllers:
            v = g.loc[g["controller"] == c, metric].to_numpy(dtype=float)
            fin = v[np.isfinite(v) & (v > 0)]
            data.append(fin if fin.size else np.array([np.nan]))
            labels.append(c)
        bp = ax.boxplot(data, showfliers=True, patch_artist=True, widths=0.6)
        for patch, c in zip(bp["boxes"], controllers):
            patch.set_facecolor(colors[c])
            patch.set_alpha(0.6)
        for k, c in enumerate(controllers):
            v = g.loc[g["controller"] == c, metric].to_numpy(dtype=float)
            n_inf = int(np.isinf(v).sum())
            if n_inf:
                ax.annotate(f"{n_inf} inf", (k + 1, 1.0), xycoords=("data", "axes fraction"), ha="center",
                            va="top", fontsize=6, color="crimson")
        ax.set_yscale("log")
        ax.set_xticks(range(1, len(controllers) + 1), labels, rotation=60, fontsize=7)
        ax.set_title(t, fontsize=9)
        ax.grid(axis="y", alpha=0.3)
    axes[0].set_ylabel(f"{metric} ({unit})")
    fig.suptitle(f"{desc}: completed runs of every task (inf: failed or never settled)", fontsize=9)
    fig.tight_layout()
    return fig


def figure_trajectories(reps: Mapping, task: str, tiers: Sequence[str], controllers: Sequence[str], seeds: Mapping):
    """Representative runs of one task, one row per tier.

    Left: top view of the navigation point (where the path metrics are measured) on the path. Right: the
    virtual point's |e|(t), the error a tracking law drives to zero.
    """
    from matplotlib.figure import Figure

    colors = _colors(controllers)
    fig = Figure(figsize=(10, 2.9 * len(tiers)))
    axes = np.atleast_2d(fig.subplots(len(tiers), 2))
    for row, t in zip(axes, tiers):
        ax_xy, ax_e = row
        runs = reps.get((t, task), {})
        drawn_ref = False
        for c in controllers:
            res = runs.get(c)
            if res is None:
                continue
            ch = res.channels
            if not drawn_ref:
                ax_xy.plot(ch["yd"], ch["xd"], "k--", lw=1, label="reference")
                drawn_ref = True
            ax_xy.plot(ch["y"], ch["x"], color=colors[c], lw=1, label=c)
            e = np.sqrt(ch["ex"] ** 2 + ch["ey"] ** 2 + ch["ez"] ** 2)
            ax_e.semilogy(ch["t"], np.maximum(e, 1e-9), color=colors[c], lw=1,
                          label=c + ("" if res.ok else f" ({res.failure['cause']} at {res.failure['time']:.1f} s)"))
        ax_xy.set_aspect("equal", adjustable="datalim")
        ax_xy.set_xlabel("east y (m)")
        ax_xy.set_ylabel("north x (m)")
        ax_xy.set_title(f"{task} / {t}: seed index {seeds.get((t, task), '?')}", fontsize=9)
        ax_e.set_xlabel("t (s)")
        ax_e.set_ylabel("virtual-point |e| (m)")
        ax_e.grid(alpha=0.3)
        ax_e.legend(fontsize=6)
    axes[0][0].legend(fontsize=6)
    fig.tight_layout()
    return fig


def _cell_rows(analysis: Mapping, tier: str, controllers: Sequence[str], tasks: Sequence[str]) -> list[list]:
    cells = {(c["tier"], c["task"], c["controller"]): c for c in analysis["cells"]}
    scores = analysis["scores"]["cells"]
    rows = []
    for task in tasks:
        for ctrl in controllers:
            c = cells[(tier, task, ctrl)]
            row = [task, ctrl, f"{c['failures']}/{c['n']} {_pct_ci(*c['failure_ci'])}"]
            for m in analysis["metrics"]:
                row.append(f"{fmt(c[m]['median'], 3)} {_ci(c[m]['low'], c[m]['high'])}")
            row.append(scores[f"{tier}/{task}"][ctrl]["score"])
            rows.append(row)
    return rows


def _paired_rows(analysis: Mapping, tier: str, criterion: str, test: str) -> list[list]:
    rows = []
    for r in analysis["paired"]:
        if r["tier"] != tier or r["criterion"] != criterion or r["test"] != test:
            continue
        rows.append([f"{r['a']} vs {r['b']}", r["n"], f"{r['n_less']} / {r['n_greater']} / {r['n_ties']}",
                     r["median_difference"], r["effect"], r["p_value"], r["p_holm"]])
    return rows


def _settings_rows(suite: Suite) -> list[list]:
    f = suite.file
    return [["suite", f"{suite.name} version {f.version} ({suite.source})" + (", quick variant" if suite.quick else "")],
            ["seeds per cell", suite.seeds], ["suite seed", f.seed],
            ["RK4 step / vehicle", f"{f.base.get('sim.dt')} s / {f.base.get('vehicle.preset')} (l = "
                                   f"{f.base.get('vehicle.l')} m)"],
            ["settling threshold", f.metrics.settle],
            ["intervals", f"{f.confidence:.0%}: Wilson (failure rates), percentile bootstrap of the median with "
                          f"{suite.bootstrap_resamples} resamples (seeded)"],
            ["scoring weights", ", ".join(f"{c} {w:g}" for c, w in f.scoring.weights().items())],
            ["fingerprint", suite.fingerprint()[:16]]]


def _load(avg) -> str:
    return "n/a" if not avg else "/".join(f"{x:.2f}" for x in avg)


def write_report(out: Path, suite: Suite, entries: Sequence[ControllerEntry], df, analysis: Mapping,
                 seeds: Mapping, reps: Mapping, timing: dict, t_analysis0: float,
                 tuned_dir: Path | None = None) -> Path:
    """Write ``report.md`` (and ``report.html``), ``results.json`` and the figures under ``out``.

    Parameters
    ----------
    out : Path
        Output folder.
    suite : Suite
        The suite.
    entries : sequence of ControllerEntry
        The competitors.
    df : pandas.DataFrame
        Runs with the derived metrics.
    analysis : mapping
        From :func:`auvtrack.benchmark.compare.analyse`.
    seeds : mapping
        Representative seed index per (tier, task).
    reps : mapping
        Representative runs ``{(tier, task): {controller: Result}}``.
    timing : dict
        Execution timing (recorded under ``timing`` in ``results.json``).
    t_analysis0 : float
        ``time.perf_counter()`` when the analysis started.
    tuned_dir : Path, optional
        Where ``compare --tune`` tuned the plug-ins (their rows of the tuning table).

    Returns
    -------
    Path
        ``report.md``.
    """
    from .. import __version__
    from ..jit import source_hash

    controllers = [e.label for e in entries]
    tiers, tasks = suite.tiers, suite.tasks
    metrics, primary = analysis["metrics"], suite.file.scoring.primary()
    scores = analysis["scores"]
    order = scores["order"]
    pooled = {r["controller"]: r for r in analysis["pooled"]}
    rep = Report(out, f"Benchmark {suite.name}: AUV trajectory-tracking control")
    if suite.quick:
        rep.paragraph("**Quick variant** (CI): few seeds and short runs; the numbers are a smoke test, "
                      "not a benchmark result.")
    rep.paragraph(
        f"{len(controllers)} controllers x {len(tasks)} tasks x {len(tiers)} tiers x {suite.seeds} seeds = "
        f"{len(df)} runs, every controller on the same seeds (common random numbers). auvtrack {__version__}, "
        f"sources {source_hash()[:12]}, suite `{suite.name}` version {suite.file.version}. "
        "Definitions, the scoring rule and how to cite: `docs/benchmark.md`.")
    if suite.skipped_tiers:
        rep.paragraph("Tiers not run in this build: " + "; ".join(f"`{t}` ({why})" for t, why in
                                                              suite.skipped_tiers.items()) + ".")

    rep.heading("Leaderboard")
    rows = []
    for c in order:
        ri = analysis["rank_intervals"][c]
        p = pooled[c]
        rows.append([scores["overall"][c]["rank"], c, f"{scores['overall'][c]['score']:.2f}",
                     f"[{ri['low']:g}, {ri['high']:g}]", ri["p_best"]]
                    + [f"{scores['tiers'][t][c]['score']:.2f} ({scores['tiers'][t][c]['rank']:g})" for t in tiers]
                    + [f"{_pct(p['failure_rate'])} {_pct_ci(*p['failure_ci'])}"])
    rep.table(["rank", "controller", "score", "rank 95 % CI", "P(best)"] + [f"{t} score (rank)" for t in tiers]
              + ["failure rate, all runs [Wilson 95 %]"], rows, digits=3)
    rep.paragraph("Score: in every (tier, task) cell the controllers are ranked on the failure rate and on "
                  "the median of each metric (a failed run counts as worse than any completed one; ties share "
                  "their average rank); the cell score is the weighted mean of these ranks, a tier's score the "
                  "mean over its tasks, the overall score the mean over the tiers. Lower is better. Rank "
                  "interval and P(best): the rule applied to resamples of the seed indices.")
    tuning = tuning_rows(entries, tuned_dir)
    suite_id = f"{suite.name} v{suite.file.version}"
    untuned = not_tuned_on(tuning, suite_id)
    if untuned:
        rep.paragraph(f"**Not tuned on this suite** ({len(untuned)} of {len(entries)}): " + ", ".join(
            f"`{c}`" for c in untuned) + f". Their gains were not tuned by `auvtrack tune` on {suite_id}'s training "
            "split (the tuning table below says where they come from); their rows rank those gains, not the "
            "controller at its best on this suite.")
    rep.figure(figure_leaderboard(analysis, tiers), "leaderboard", "Overall and per-tier scores; rank intervals")
    write_aggregates_section(rep, analysis["aggregates"], order)

    rep.heading("Settings")
    rep.table(["setting", "value"], _settings_rows(suite))
    rep.table(["controller", "gains"], [[e.label, e.gains] for e in entries])
    if any("defaults" in e.gains for e in entries):
        rep.paragraph("Controllers without a tuned gain preset run with their package defaults (above).")
    rep.paragraph("Tuning of each competitor, from its gain preset's provenance (`auvtrack tune` writes it; "
                  "docs/tuning.md): what it was tuned on, the budget and what it cost.")
    rep.table(list(TUNING_COLUMNS), tuning)
    gains = gain_rows(entries)
    if gains:
        rep.paragraph("Gains the presets change, next to the published values (the controllers' defaults, "
                      "docs/controllers.md):")
        rep.table(["competitor", "gain", "published", "preset", "preset name"], gains)
    rep.table(["task", "duration (s)", "description"],
              [[t, suite.duration(t), suite.file.tasks[t].description] for t in tasks])
    rep.table(["tier", "description"], [[t, suite.file.tiers[t].description] for t in tiers])

    rep.heading("Failures")
    rep.figure(figure_failures(analysis, tiers, controllers), "failure_rates",
               "Failure rate per tier (pooled over tasks) with Wilson 95 % intervals")
    rows = []
    for r in analysis["pooled_tier"]:
        causes = ", ".join(f"{k} {v}" for k, v in r["causes"].items()) or "none"
        rows.append([r["tier"], r["controller"], f"{r['failures']}/{r['n']}", _pct(r["failure_rate"]),
                     _pct_ci(*r["failure_ci"]), causes])
    rep.table(["tier", "controller", "failed", "rate", "Wilson 95 %", "causes"], rows)
    head, why = failure_cause_rows(analysis["pooled_tier"])
    if why:
        rep.paragraph("Why it failed: the failed runs of every tier and controller by cause (pooled over the "
                      "tasks; `unknown`: a failure without a recorded cause).")
        rep.table(head, why)
    else:
        rep.paragraph("No run failed.")
    setup = df[df["cause"] == "setup"]
    if len(setup):
        rep.paragraph("Runs refused at set-up (counted as failures): " + "; ".join(
            f"{c}: {d} ({n} runs)" for (c, d), n in setup.groupby(["controller", "detail"]).size().items()))

    for t in tiers:
        rep.heading(f"Tier `{t}`")
        rep.paragraph(suite.file.tiers[t].description)
        rep.table(["task", "controller", "failed [Wilson 95 %]"] + [_header(m) for m in metrics]
                  + ["cell score"], _cell_rows(analysis, t, order, tasks), digits=3)
        prs = _paired_rows(analysis, t, primary, "wilcoxon")
        if prs:
            rep.paragraph(f"Paired `{primary}` comparisons on the same (task, seed) pairs: Wilcoxon signed-rank test; "
                          "effect = rank-biserial correlation of a - b (negative: a smaller); p Holm-adjusted "
                          "over the pairs of this tier. Every criterion and the sign tests: `results.json`.")
            rep.table(["pair", "n", "a < b / a > b / tie", "median a - b", "effect r", "p", "p (Holm)"], prs,
                      digits=3)

    rep.heading("Distributions")
    for m in metrics:
        desc, unit = metric_info(m)
        rep.figure(figure_distribution(df, m, tiers, order), f"dist_{m}", f"{m}: {desc} ({unit})")

    rep.heading("Representative trajectories")
    rep.paragraph(f"Per tier, the seed at the median of the controllers' median `{primary}`, re-run with its trajectory "
                  "(the same seed for every controller). Left: the navigation point's track (where the path metrics "
                  "are measured) over the path; right: the virtual point's error |e|, the point a tracking law "
                  "steers, ℓ ahead of the navigation point (a path follower such as the LOS autopilot puts the "
                  "navigation point on the path, so its |e| stays about ℓ by design).")
    for task in tasks:
        rep.figure(figure_trajectories(reps, task, tiers, order, seeds), f"traj_{task}", f"{task}")

    rep.heading("Metrics")
    rep.table(["metric", "definition", "unit"], [[m, *metric_info(m)] for m in metrics])
    rep.paragraph("Whole-run metrics of the engine (`docs/metrics.md`) combined over the axes / inputs; "
                  "`inf` = a failed run, or a settling time that never came.")
    rep.heading("Reproduce")
    cmd = "auvtrack compare --suite " + suite.name + (" --quick" if suite.quick else "")
    rep.paragraph(f"`{cmd}` with auvtrack {__version__} (sources {source_hash()[:12]}) gives the same numbers "
                  "(every random number derives from the suite seed). Wall time of the runs: "
                  f"{timing['runs_seconds']:.1f} s after {timing['compile_seconds']:.1f} s of kernel compilation "
                  f"or loading ({timing['backend']}, batch back end {timing.get('batch_backend')}, "
                  f"{timing['chunks_run']} chunks run now, "
                  f"{timing['chunks_resumed']} resumed), on {platform.machine()} with "
                  f"{timing.get('cpu_count')} cores / Python {platform.python_version()}; load average (1, 5, "
                  f"15 min) {_load(timing.get('load_average_start'))} at the start, "
                  f"{_load(timing.get('load_average_end'))} at the end of the runs.")
    rep.scenario(suite.text or suite.settings(), f"Suite `{suite.name}` ({suite.source}): every task, tier and "
                 "setting of the runs (each run's scenario: `auvtrack.benchmark.suite.Suite.scenario`)")
    report = rep.write()
    timing = dict(timing, analysis_seconds=time.perf_counter() - t_analysis0)
    write_json(out / "results.json", {
        "suite": suite.settings(), "controllers": [e.to_dict() for e in entries],
        "auvtrack_version": __version__, "source_hash": source_hash(), "criteria": list(analysis["criteria"]),
        "metrics": {m: dict(zip(("description", "unit"), metric_info(m))) for m in metrics},
        "leaderboard": [{"controller": c, **scores["overall"][c], "rank_interval": analysis["rank_intervals"][c],
                         "tiers": {t: scores["tiers"][t][c] for t in tiers}} for c in order],
        "representative_seeds": {f"{k[0]}/{k[1]}": v for k, v in seeds.items()},
        "tuning": [dict(zip(TUNING_COLUMNS, r)) for r in tuning], "not_tuned_on_suite": untuned,
        **{k: analysis[k] for k in ("cells", "pooled_tier", "pooled", "scores", "weights", "paired", "aggregates")},
        "timing": timing,
    })
    return report
