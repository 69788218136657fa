"""Why the auv-track-v2 PID preset misses the helix on Fossen's truth: the runs, stored, and the doc block.

The tuned PID of auv-track-v2 (``pid_remus100_auv-track-v2``) has a median ``xtrack_rmse`` above
the acceptance's 0.5 m on the ``truth_fossen`` / ``helix`` cell, while the older preset
``pid_tuned`` stays below it.  This tool flies the PID with a few gain sets on the runs that
decide it, exactly as ``auvtrack compare`` and ``auvtrack tune`` build them
(:meth:`auvtrack.benchmark.suite.Suite.scenario`, :func:`auvtrack.benchmark.execute.run_chunk`,
the suite's run score):

* the training split (every cell, the seeds ``auvtrack tune`` scores: its objective is the mean
  run score over these runs);
* the ``helix`` / ``truth_fossen`` cell on the training seeds and on the evaluation seeds;
* the ``digital`` tier on the evaluation seeds (where the PID's candidates fail).

Commands::

    python -m tools.pid_preset_gap run STUDY  # fly the runs, write docs/results/pid-preset-gap.json
                                              # (STUDY: the shipped preset's `auvtrack tune --out` folder)
    python -m tools.pid_preset_gap render   # rewrite the generated block of docs/tuning.md
    python -m tools.pid_preset_gap check    # exit status 1 when the block differs from the stored result

``tests/docs/test_pid_preset_gap.py`` runs ``check`` and ties the stored shipped-preset cell to
the stored comparison (``docs/results/compare-v2.json``).  Importing this module runs nothing.
"""
from __future__ import annotations

import datetime as _dt
import json
import math
import re
import sys
import time
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
RESULT = ROOT / "docs" / "results" / "pid-preset-gap.json"
DOC = ROOT / "docs" / "tuning.md"
NAME = "pid-preset-gap"
BLOCK_RE = re.compile(rf"(<!-- BEGIN GENERATED {NAME}[^>]*-->\n)(.*?)(<!-- END GENERATED {NAME} -->)", re.S)
SUITE = "auv-track-v2"
SHIPPED = "pid_remus100_auv-track-v2"
OLD = "pid_tuned"
CELL = ("helix", "truth_fossen")
DIGITAL = "digital"
BACKEND = "simd"
XTRACK_TARGET = 0.5  # m, the acceptance's bound on a calm truth cell's median cross-track error
KP_FACTORS = (0.5, 1.5)
"""Factors on the shipped preset's kp, flown with its other gains."""
EARLY_BUDGET = 20
"""Trials of the first auv-track-v2 presets: the shipped study's best among its first trials is flown too."""
COLUMNS = ("xtrack_rmse", "xtrack_rmse_late", "vtrack_rmse", "energy", "tv", "act_rate_q", "act_rate_r",
           "t_act_limit_q", "t_act_limit_r")
GAINS = ("kp", "ki", "kd", "kaw", "saturation")


def first_best(trials: list[dict[str, Any]], budget: int = EARLY_BUDGET) -> dict[str, Any]:
    """The best completed trial among the first ``budget`` trials of the shipped preset's study."""
    done = [t for t in trials if t["number"] < budget and t["state"] == "COMPLETE"]
    if not done:
        raise ValueError(f"no trial of the first {budget} completed")
    return min(done, key=lambda t: (t["value"], t["number"]))


def variants(trials: list[dict[str, Any]]) -> dict[str, tuple[dict[str, Any], str]]:
    """Label -> (the ``[controller]`` table flown, what it is).

    The shipped preset; the best trial of the first :data:`EARLY_BUDGET` of its own study (the
    same search stopped at the earlier presets' budget); the old preset; the designed gains (the
    tuning's first trial); the shipped preset with its kp scaled by :data:`KP_FACTORS`.

    Parameters
    ----------
    trials : list of dict
        The shipped preset's study: ``number``, ``state``, ``value``, ``params`` per trial.
    """
    from auvtrack.control.gain_presets import get_gain_preset

    shipped = dict(get_gain_preset(SHIPPED).gains)
    prov = get_gain_preset(SHIPPED).provenance
    early = first_best(trials)
    out: dict[str, tuple[dict[str, Any], str]] = {
        "shipped": ({"kind": "pid", "preset": SHIPPED}, f"`{SHIPPED}`, the shipped preset ({prov['sampler'].upper()}, "
                    f"{prov['budget_trials']} trials)"),
        "early": ({"kind": "pid", **shipped, **early["params"]},
                  f"the best of the same study's first {EARLY_BUDGET} trials (trial {early['number']})"),
        "old": ({"kind": "pid", "preset": OLD}, f"`{OLD}`, differential evolution on the paper's vehicle (docs below)"),
        "designed": ({"kind": "pid"}, "the designed gains (the tuning's trial 0, the untuned PID)"),
    }
    for f in KP_FACTORS:
        kp = f * float(shipped["kp"])
        out[f"shipped, kp x {f:g}"] = ({"kind": "pid", **shipped, "kp": kp},
                                       f"the shipped preset with kp x {f:g} = {kp:.4g}")
    return out


def study_trials(folder: Path) -> list[dict[str, Any]]:
    """The trials of the ``auvtrack tune`` study in ``folder`` that produced the shipped preset.

    Raises
    ------
    ValueError
        The study's best training score is not the shipped preset's.
    """
    from auvtrack.control.gain_presets import get_gain_preset

    res = json.loads((Path(folder) / "results.json").read_text())
    want = get_gain_preset(SHIPPED).provenance["train_score"]
    if res["result"]["best_score"] != want:
        raise ValueError(f"{folder}: its best training score {res['result']['best_score']} is not the shipped "
                         f"preset's {want}")
    return [{"number": t["number"], "state": t["state"], "value": t["value"], "params": t["params"]}
            for t in res["trials"]]


def _suite():
    from auvtrack.benchmark.suite import load_suite

    return load_suite(SUITE, check=False)


def _resolved(table: dict[str, Any]) -> dict[str, Any]:
    """The gains a ``[controller]`` table resolves to on the first training run of the cell."""
    from auvtrack.benchmark.execute import RunSpec, _prepare
    from auvtrack.benchmark.suite import ControllerEntry

    suite = _suite()
    raw, ov, drawn = suite.scenario(ControllerEntry("x", dict(table), "x"), *CELL, suite.split_seeds("training")[0])
    prep = _prepare(RunSpec(0, "x", *CELL, 0, raw, ov, drawn))
    if isinstance(prep, str):
        raise ValueError(f"{table}: refused at set-up: {prep}")
    ctl = prep.scenario.controller.model_dump()
    return {k: ctl[k] for k in GAINS}


def _fly(suite, table: dict[str, Any], cells: list[tuple[str, str]], seeds: range):
    """The runs of ``cells`` x ``seeds`` for one controller table, with derived metrics and run scores."""
    from auvtrack.benchmark.execute import RunSpec, run_chunk
    from auvtrack.benchmark.leaderboard import derive_metrics
    from auvtrack.benchmark.suite import ControllerEntry

    entry = ControllerEntry("pid", dict(table), "flown by tools.pid_preset_gap")
    specs = []
    for task, tier in cells:
        for i in seeds:
            raw, ov, drawn = suite.scenario(entry, task, tier, i)
            specs.append(RunSpec(len(specs), "pid", task, tier, i, raw, ov, drawn))
    df = derive_metrics(run_chunk(specs, workers=None, backend=BACKEND).to_pandas(), settle=suite.file.metrics.settle)
    df["score"] = [suite.run_score(r, r["task"]) for r in df.to_dict("records")]
    return df


def _terms(suite, df) -> dict[str, float]:
    """Mean share of each weighted criterion in the run score of the completed runs (they add up to its mean)."""
    rs = suite.file.run_score
    total = sum(w for w in rs.weights.values() if w > 0)
    ok = df[df["status"] == "ok"]
    out = {}
    for c, w in rs.weights.items():
        if w > 0:
            v = ok[c].to_numpy(dtype=float) / rs.scales[c]
            v[~(v < rs.cap)] = rs.cap
            out[c] = float((w * v).mean() / total) if len(ok) else math.nan
    return out


def _summary(suite, df) -> dict[str, Any]:
    """Failures (by cause), medians and maxima of :data:`COLUMNS`, mean run score and its terms."""
    ok = df[df["status"] == "ok"]
    failed = df[df["status"] != "ok"]
    causes: dict[str, int] = {}
    for (task, tier, cause), n in failed.groupby(["task", "tier", "cause"]).size().items():
        causes[f"{task}/{tier}/{cause or 'unknown'}"] = int(n)
    return {"runs": len(df), "failures": len(failed), "failures_by_cell_cause": causes,
            "score_mean": float(df["score"].mean()),
            "median": {c: float(ok[c].median()) if len(ok) else math.nan for c in COLUMNS},
            "max": {c: float(ok[c].max()) if len(ok) else math.nan for c in COLUMNS},
            "score_terms": _terms(suite, df)}


def run(study: Path, out: Path = RESULT) -> Path:
    """Fly every variant on the runs of the module docstring and write the summary to ``out``.

    Parameters
    ----------
    study : pathlib.Path
        The ``auvtrack tune --out`` folder of the shipped preset (its trials are stored too).
    out : pathlib.Path, optional
        The JSON file written (default ``docs/results/pid-preset-gap.json``).

    Returns
    -------
    pathlib.Path
        ``out``.
    """
    from auvtrack.control.gain_presets import get_gain_preset
    from auvtrack.jit import source_hash

    trials = study_trials(study)
    suite = _suite()
    training, evaluation = suite.split_seeds("training"), suite.split_seeds("evaluation")
    t0 = time.perf_counter()
    result: dict[str, Any] = {"suite": {"name": suite.name, "version": suite.file.version,
                                        "training_seeds": [training.start, training.stop],
                                        "evaluation_seeds": [evaluation.start, evaluation.stop],
                                        "training_cells": [list(c) for c in suite.split_cells("training")],
                                        "run_score": suite.file.run_score.model_dump(mode="json")},
                              "cell": list(CELL), "backend": BACKEND, "variants": {},
                              "shipped_tuning": {k: get_gain_preset(SHIPPED).provenance.get(k) for k in
                                                 ("budget_trials", "complete", "pruned", "refused", "sampler",
                                                  "train_score")},
                              "trials": trials}
    for label, (table, what) in variants(trials).items():
        train = _fly(suite, table, suite.split_cells("training"), training)
        cell_eval = _fly(suite, table, [CELL], evaluation)
        digital = _fly(suite, table, [(t, DIGITAL) for t in suite.tasks], evaluation)
        cell_train = train[(train["task"] == CELL[0]) & (train["tier"] == CELL[1])]
        result["variants"][label] = {
            "table": table, "what": what, "gains": _resolved(table),
            "training": _summary(suite, train), "cell_training": _summary(suite, cell_train),
            "cell_evaluation": _summary(suite, cell_eval), "digital_evaluation": _summary(suite, digital)}
        print(f"{label}: training score {result['variants'][label]['training']['score_mean']:.4f}", file=sys.stderr)
    result["_provenance"] = {"command": "python -m tools.pid_preset_gap run STUDY",
                             "stored": _dt.datetime.now(_dt.timezone.utc).strftime("%Y-%m-%d %H:%M UTC"),
                             "source_hash": source_hash()[:16], "seconds": round(time.perf_counter() - t0, 1)}
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(json.dumps(result, indent=1, allow_nan=False) + "\n")
    return out


# ------------------------------------------------------------------ the doc block
def _g(x: float, d: int = 3) -> str:
    return f"{x:.{d}g}"


def _fails(s: dict[str, Any]) -> str:
    if not s["failures"]:
        return "0"
    causes: dict[str, int] = {}
    for key, n in s["failures_by_cell_cause"].items():
        causes[key.rsplit("/", 1)[1]] = causes.get(key.rsplit("/", 1)[1], 0) + n
    return f"{s['failures']} ({', '.join(f'{k} {v}' for k, v in sorted(causes.items()))})"


def _require(ok: bool, what: str) -> None:
    if not ok:
        raise ValueError(f"{RESULT.name}: the doc's reading no longer holds ({what}); rewrite tools/pid_preset_gap.block")


def block(res: dict[str, Any]) -> str:
    """The generated block of docs/tuning.md from a stored result of :func:`run`.

    Parameters
    ----------
    res : dict
        The stored JSON.

    Returns
    -------
    str
        Markdown: provenance, the table of every variant and the reading of it.
    """
    v = res["variants"]
    s, task, tier = res["suite"], *res["cell"]
    n_train = v["shipped"]["training"]["runs"]
    n_cell_t, n_cell_e = v["shipped"]["cell_training"]["runs"], v["shipped"]["cell_evaluation"]["runs"]
    n_dig = v["shipped"]["digital_evaluation"]["runs"]
    head = (f"`{res['_provenance']['command']}`, stored {res['_provenance']['stored']} (sources "
            f"{res['_provenance']['source_hash'][:12]}, {res['backend']} back end): {s['name']} v{s['version']}; "
            f"training split: {len(s['training_cells'])} cells x seeds {s['training_seeds'][0]}-"
            f"{s['training_seeds'][1] - 1} ({n_train} runs, the runs `auvtrack tune` scores); the `{task}` / "
            f"`{tier}` cell on those seeds ({n_cell_t} runs) and on the evaluation seeds "
            f"{s['evaluation_seeds'][0]}-{s['evaluation_seeds'][1] - 1} ({n_cell_e} runs, those of `auvtrack compare`); "
            f"the `{DIGITAL}` tier on the evaluation seeds ({n_dig} runs).")
    rows = ["| gains | kp | ki | kd | kaw | training objective (mean run score) | training runs failed | "
            f"{task}/{tier} median `xtrack_rmse` (m), training / evaluation seeds | late `xtrack_rmse` (m), "
            "evaluation | median energy (N² s) | time at a fin limit, max (s) q / r | mean run score of the cell, "
            f"evaluation | {DIGITAL} tier, evaluation runs failed |",
            "|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for label, r in v.items():
        g, ce = r["gains"], r["cell_evaluation"]
        rows.append(f"| {r['what']} | {_g(g['kp'], 4)} | {_g(g['ki'], 3)} | {_g(g['kd'], 4)} | {_g(g['kaw'], 3)} | "
                    f"{r['training']['score_mean']:.3f} | {_fails(r['training'])} | "
                    f"{_g(r['cell_training']['median']['xtrack_rmse'])} / {_g(ce['median']['xtrack_rmse'])} | "
                    f"{_g(ce['median']['xtrack_rmse_late'])} | {ce['median']['energy']:.0f} | "
                    f"{_g(ce['max']['t_act_limit_q'])} / {_g(ce['max']['t_act_limit_r'])} | "
                    f"{ce['score_mean']:.3f} | {_fails(r['digital_evaluation'])} |")
    sh, early, old, des, tu = v["shipped"], v["early"], v["old"], v["designed"], res["shipped_tuning"]
    target = XTRACK_TARGET

    def med(r: dict, part: str = "cell_evaluation", col: str = "xtrack_rmse") -> float:
        return r[part]["median"][col]

    family = sorted((r for r in v.values() if all(r["gains"][k] == sh["gains"][k] for k in ("ki", "kd", "kaw"))),
                    key=lambda r: r["gains"]["kp"])
    product = [med(r) * r["gains"]["kp"] for r in family]
    failing = [r for r in v.values() if r["training"]["failures"]]
    where = sorted({k.split("/", 1)[1] for r in failing for k in r["training"]["failures_by_cell_cause"]})
    tiers = sorted({w.split("/")[0] for w in where})
    causes = sorted({w.split("/")[1] for w in where})
    dig = sh["digital_evaluation"]
    # the reading below holds only for results that show it; a result that does not stops the rendering
    _require(sh["cell_training"]["failures"] == sh["cell_evaluation"]["failures"] == 0, "the shipped preset fails the cell")
    _require(sh["training"]["failures"] == 0 and early["training"]["failures"] == 0,
             "the shipped or the early preset fails a training run")
    _require(med(sh) <= target < med(early), "the budget no longer decides the cell")
    _require(sh["training"]["score_mean"] < early["training"]["score_mean"], "the longer search has no lower objective")
    _require(len(family) >= 3 and max(product) < 1.25 * min(product), "the error x kp is not about constant")
    _require(abs(med(sh, col="xtrack_rmse_late") - med(sh)) < 0.1 * med(sh), "the shipped error is not steady")
    _require(sh["gains"]["ki"] < 1e-3, "the shipped preset has integral action")
    _require(bool(failing) and all(med(r) <= target for r in failing) and tiers == [DIGITAL],
             "the gain sets that fail training are not those that meet the bound, in the digital tier")
    text = [
        f"* **The budget decides the cell.** The shipped preset ({tu['budget_trials']} trials: {tu['complete']} "
        f"completed, {tu['pruned']} pruned at a failed run, {tu['refused']} refused at set-up) completes the training "
        f"split and its median on the cell is {_g(med(sh, 'cell_training'))} m on the training seeds and "
        f"{_g(med(sh))} m on the evaluation seeds, within {target:g} m. {early['what'][0].upper()}{early['what'][1:]}, "
        f"at the budget of the first auv-track-v2 presets, completes the training split too, with a higher objective "
        f"({early['training']['score_mean']:.3f} against {sh['training']['score_mean']:.3f}), and misses the cell "
        f"with {_g(med(early))} m: the objective and the acceptance agree here; the short search had not reached "
        "the stiffer gains.",
        "* **A steady offset held by kp alone.** The late-window error "
        f"({_g(med(sh, col='xtrack_rmse_late'))} m) is the whole run's: the vehicle settles beside the helix. The "
        f"shipped preset has practically no integral action (ki = {_g(sh['gains']['ki'], 2)}); with its other "
        "gains, kp = " + ", ".join(f"{_g(r['gains']['kp'], 4)}" for r in family)
        + " gives medians of " + ", ".join(f"{_g(med(r))}" for r in family)
        + f" m: median x kp stays within [{_g(min(product))}, {_g(max(product))}] m/s², an offset close to 1/kp, "
        "as a proportional term leaves against a constant acceleration the 6-DOF truth adds to the design model. "
        f"The designed gains, integral action with anti-windup (ki = {_g(des['gains']['ki'])}, kaw = "
        f"{_g(des['gains']['kaw'], 2)}), reach {_g(med(des))} m.",
        f"* **Why not stiffer: failures first.** Every training failure of these gain sets is in the `{DIGITAL}` "
        f"tier, by {' or '.join(f'`{c}`' for c in causes)} (sampled control, sensor noise, saturated and "
        "rate-limited actuators: docs/benchmark.md). A failed run scores at least "
        f"cap + 1 = {res['suite']['run_score']['cap'] + 1:g} and `auvtrack tune` prunes a candidate at its first "
        f"failed run, so these lose to the shipped preset although they meet {target:g} m on the cell: "
        + "; ".join(f"{r['what']}: {r['training']['failures']} failed training runs, objective "
                    f"{r['training']['score_mean']:.3f}, {_g(med(r))} m" for r in failing) + ".",
        f"* **The margin.** {_g(med(sh))} m against {target:g} m on the cell. On the `{DIGITAL}` tier's evaluation "
        f"runs the shipped preset fails {_fails(dig)} of {dig['runs']}: the acceptance asks for no failure on the "
        "calm truth tiers; the digital tier's failures count in the leaderboard.",
    ]
    return head + "\n\n" + "\n".join(rows) + "\n\n" + "\n".join(text)


def render_text(text: str, res: dict[str, Any]) -> str:
    """``text`` with its generated block replaced by :func:`block` of ``res``."""
    if not BLOCK_RE.search(text):
        raise ValueError(f"{DOC.name}: no <!-- BEGIN GENERATED {NAME} --> block")
    return BLOCK_RE.sub(lambda m: m.group(1) + block(res) + "\n" + m.group(3), text)


def main(argv: list[str] | None = None) -> int:
    """``run``, ``render`` or ``check`` (module docstring); returns the exit status."""
    args = sys.argv[1:] if argv is None else argv
    if args[:1] == ["run"] and len(args) in (2, 3):
        print(run(Path(args[1]), Path(args[2]) if len(args) > 2 else RESULT))
        return 0
    if args[:1] not in (["render"], ["check"]):
        print("usage: python -m tools.pid_preset_gap run STUDY [OUT.json] | render | check", file=sys.stderr)
        return 2
    res = json.loads(RESULT.read_text())
    text = DOC.read_text()
    new = render_text(text, res)
    if args[0] == "render":
        DOC.write_text(new)
        return 0
    if new != text:
        print(f"{DOC.relative_to(ROOT)}: the {NAME} block differs from {RESULT.relative_to(ROOT)}; run "
              "python -m tools.pid_preset_gap render", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
