"""``auvtrack study robustness``: Monte Carlo over model error, disturbance and initial state.

Each sample draws, independently and uniformly (numpy ``default_rng`` seeded from the study
seed, so a sample set is a pure function of ``(seed, n)``):

* the true plant's model error: ``uncertainty.M``, ``uncertainty.D`` and ``uncertainty.C`` in
  [-0.3, 0.3] (M_true = (1 + M) M, D_true = (1 + D) D0, C_true = (1 + C) C0(nu; M_true): each
  matrix off by up to +-30 %, one factor per matrix, see ``docs/vehicles.md``);
* the paper's disturbance with amplitude in [0, 2] (x the printed one) and phase in [0, 2 pi);
* the initial state: Section 4's eta(0) = [0, 0.5, 0, 0, 0] plus offsets in x, y (+-1 m),
  z (+-0.5 m) and psi (+-0.3 rad);
* the scenario seed (RBF centres and initial weights of the FXTNTSMC).

Every controller configuration sees the *same* samples (common random numbers), on every
vehicle preset of the configuration (``paper`` and ``remus100`` by default).  Runs go through
:func:`auvtrack.batch.runner.run_batch` (threads over the ``nogil`` kernel).  The report
gives, per vehicle and controller, the failure rate with the failures by cause, and the median
and 95th percentile of the metrics over the runs that did not fail.
"""
from __future__ import annotations

import math
import time
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any, Sequence

import numpy as np

from ..scenario import load_scenario
from ..simulation.compiling import compile_first
from ..simulation.pipeline import prepare
from ..batch.runner import run_batch
from .registry import StudySpec
from ..report import Report, failure_cause, write_json

__all__ = ["Sample", "RobustnessConfig", "CONTROLLERS", "draw_samples", "sample_scenario",
           "run_batch", "summarise", "run", "STUDY"]

MODEL_ERROR = 0.3  # +-30 % on M, D0, C0
AMPLITUDE = (0.0, 2.0)
OFFSET = (1.0, 1.0, 0.5, 0.0, 0.3)  # half-widths on x, y, z (m), theta, psi (rad)
ETA0 = (0.0, 0.5, 0.0, 0.0, 0.0)
LOG_DT = 0.1  # s; the last-quarter max |e| is taken from the log
AXES = ("x", "y", "z")
INPUTS = ("u", "q", "r")

# (label, kind, gain preset or None): the package defaults and the tuned presets of docs/tuning.md
CONTROLLERS: tuple[tuple[str, str, str | None], ...] = (
    ("FXTNTSMC (paper gains)", "fxtntsmc", None),
    ("FXTNTSMC (tuned)", "fxtntsmc", "fxtntsmc_tuned"),
    ("FTSMC (default gains)", "ftsmc", None),
    ("FTSMC (tuned)", "ftsmc", "ftsmc_tuned"),
)

QUANTITIES: tuple[tuple[str, str], ...] = (
    ("settle_1cm", "time all axes stay within 1 cm (s)"),
    ("rmse", "RMSE, 3-D, whole run (m)"),
    ("max_e_late", "max |e| over the axes on the last quarter of the run (m)"),
    ("itae", "ITAE, sum over axes (m s^2)"),
    ("energy", "control energy, sum over inputs"),
    ("tv", "total variation of tau per second, sum over inputs"),
)


@dataclass(frozen=True)
class Sample:
    """One Monte Carlo draw (see the module docstring for the distributions).

    Attributes
    ----------
    index : int
        Position in the sample set; also the scenario seed.
    M, D, C : float
        Fractional model errors of the true plant, in [-0.3, 0.3].
    amplitude, phase : float
        Disturbance scale in [0, 2] and phase in [0, 2 pi) rad.
    eta0 : tuple of 5 float
        Initial [x, y, z, theta, psi].
    """

    index: int
    M: float
    D: float
    C: float
    amplitude: float
    phase: float
    eta0: tuple[float, ...]


@dataclass(frozen=True)
class RobustnessConfig:
    """Size and run settings of the study.

    Attributes
    ----------
    n : int
        Samples per vehicle.
    seed : int
        Study seed (``numpy.random.default_rng(seed)``).
    duration, dt : float
        Run length and RK4 step (s).
    vehicles : tuple of str
        Vehicle presets.
    workers : int or None
        Threads (None: the batch runner's :func:`~auvtrack.batch.runner.default_workers`).
    """

    n: int = 100
    seed: int = 0
    duration: float = 40.0
    dt: float = 0.001
    vehicles: tuple[str, ...] = ("paper", "remus100")
    workers: int | None = None


FULL = RobustnessConfig()
QUICK = RobustnessConfig(n=3, duration=3.0, dt=0.002)


def draw_samples(n: int, seed: int) -> list[Sample]:
    """Draw ``n`` samples from ``numpy.random.default_rng(seed)`` (deterministic).

    Parameters
    ----------
    n : int
        Number of samples, >= 1.
    seed : int
        Seed, >= 0.

    Returns
    -------
    list of Sample
        ``n`` samples, ``index`` 0 .. n-1.
    """
    if n < 1:
        raise ValueError(f"n: must be >= 1 (got {n})")
    rng = np.random.default_rng(seed)
    err = rng.uniform(-MODEL_ERROR, MODEL_ERROR, size=(n, 3))
    amp = rng.uniform(*AMPLITUDE, size=n)
    phase = rng.uniform(0.0, 2.0 * math.pi, size=n)
    half = np.array(OFFSET)
    off = rng.uniform(-1.0, 1.0, size=(n, 5)) * half
    return [Sample(index=i, M=float(err[i, 0]), D=float(err[i, 1]), C=float(err[i, 2]),
                   amplitude=float(amp[i]), phase=float(phase[i]),
                   eta0=tuple(float(a + b) for a, b in zip(ETA0, off[i])))
            for i in range(n)]


def sample_scenario(s: Sample, vehicle: str, kind: str, preset: str | None, duration: float,
                    dt: float) -> dict[str, Any]:
    """Scenario dict of one sample (Section 4 for everything not drawn).

    Parameters
    ----------
    s : Sample
        The draw.
    vehicle : str
        Vehicle preset.
    kind : str
        Controller kind.
    preset : str or None
        Gain preset, or None for the package defaults.
    duration, dt : float
        Run length and RK4 step (s).

    Returns
    -------
    dict
        Input of :func:`auvtrack.scenario.load_scenario`.
    """
    # the package defaults are the law's fixed defaults, not the gains designed for the vehicle
    ctrl: dict[str, Any] = {"kind": kind, "preset": "defaults" if preset is None else preset}
    return {
        "name": f"robustness-{vehicle}-{kind}-{s.index}", "seed": s.index,
        "sim": {"duration": duration, "dt": dt, "log_dt": LOG_DT},
        "vehicle": {"preset": vehicle},
        "uncertainty": {"M": s.M, "D": s.D, "C": s.C, "G": 0.0},
        "initial": {"eta": list(s.eta0)},
        "controller": ctrl,
        "disturbance": [{"kind": "paper", "amplitude": s.amplitude, "phase": s.phase}],
    }


def _record(res, duration: float) -> dict[str, Any]:
    m = res.metrics
    t = np.asarray(res.channels["t"])
    late = t >= 0.75 * duration
    e = np.vstack([res.channels[f"e{a}"] for a in AXES])
    rec = {
        "status": res.status,
        "cause": failure_cause(res),
        "fail_time": None if res.failure is None else res.failure["time"],
        "settle_1cm": max(m[f"settle_1cm_{a}"] for a in AXES),
        "rmse": math.sqrt(sum(m[f"rmse_{a}"] ** 2 for a in AXES)),
        "max_e_late": float(np.max(np.abs(e[:, late]))) if late.any() else math.nan,
        "itae": sum(m[f"itae_{a}"] for a in AXES),
        "energy": sum(m[f"energy_tau_{j}"] for j in INPUTS),
        "tv": sum(m[f"tv_tau_{j}"] for j in INPUTS),
    }
    return rec


def summarise(records: Sequence[dict]) -> dict[str, Any]:
    """Failure rate, failures by cause, and median / 95th percentile of each quantity.

    Quantiles (``inverted_cdf``) are over the runs that did not fail; ``inf`` (e.g. never
    within 1 cm) counts as larger than any number.

    Parameters
    ----------
    records : sequence of dict
        Per run: ``status``, ``cause`` and every quantity of :data:`QUANTITIES`.

    Returns
    -------
    dict
        ``n``, ``failed``, ``failure_rate``, ``causes`` (count by cause) and, per quantity,
        ``{"median", "p95", "n_inf"}``.
    """
    n = len(records)
    ok = [r for r in records if r["status"] == "ok"]
    causes: dict[str, int] = {}
    for r in records:
        if r["status"] != "ok":
            causes[r["cause"]] = causes.get(r["cause"], 0) + 1
    out: dict[str, Any] = {"n": n, "failed": n - len(ok), "failure_rate": (n - len(ok)) / n if n else math.nan,
                           "causes": causes}
    for q, _ in QUANTITIES:
        vals = np.array([r[q] for r in ok], dtype=float)
        vals = vals[~np.isnan(vals)]
        if vals.size == 0:
            out[q] = {"median": math.nan, "p95": math.nan, "n_inf": 0}
            continue
        out[q] = {"median": float(np.quantile(vals, 0.5, method="inverted_cdf")),
                  "p95": float(np.quantile(vals, 0.95, method="inverted_cdf")),
                  "n_inf": int(np.isinf(vals).sum())}
    return out


def _fmt(x: float) -> str:
    if x is None or (isinstance(x, float) and math.isnan(x)):
        return "–"
    return "inf" if math.isinf(x) else f"{x:.3g}"


def _report(out: Path, summary: dict, cfg: RobustnessConfig, quick: bool, wall: float, skipped: list[str]) -> Report:
    rep = Report(out, "Robustness: Monte Carlo over model error, disturbance and initial state")
    if quick:
        rep.paragraph("**Quick mode** (CI smoke test): a handful of short runs; the numbers are not meaningful.")
    rep.paragraph(f"{cfg.n} samples per vehicle (seed {cfg.seed}), {cfg.duration:g} s runs at dt = {cfg.dt:g} s, "
                  f"the same samples for every controller. Draws (uniform): M, D, C model errors in ±{MODEL_ERROR:.0%}; "
                  f"disturbance amplitude in [{AMPLITUDE[0]:g}, {AMPLITUDE[1]:g}] × the paper's, phase in [0, 2π); "
                  "initial x, y ± 1 m, z ± 0.5 m, ψ ± 0.3 rad around Section 4's start; scenario seed = sample index. "
                  f"Wall time {wall:.0f} s.")
    if skipped:
        rep.paragraph(f"Skipped (gain preset not installed): {', '.join(skipped)}.")
    rep.paragraph("Quantiles are over the runs that did not fail; `inf` settling = never stayed within 1 cm "
                  "(the count is given as n_inf).")
    for vehicle, per in summary.items():
        rep.heading(f"Vehicle `{vehicle}`")
        rows = []
        for label, s in per.items():
            causes = ", ".join(f"{c}: {k}" for c, k in sorted(s["causes"].items())) or "none"
            cells = []
            for q, _ in QUANTITIES:
                cell = f"{_fmt(s[q]['median'])} / {_fmt(s[q]['p95'])}"
                if s[q]["n_inf"]:
                    cell += f" (n_inf {s[q]['n_inf']})"
                cells.append(cell)
            rows.append([label, f"{s['failed']}/{s['n']} ({s['failure_rate']:.0%})", causes, *cells])
        rep.table(["controller", "failure rate", "failures by cause", *(f"{q} median / p95" for q, _ in QUANTITIES)],
                  rows)
    rep.paragraph("Quantities: " + "; ".join(f"`{q}` = {d}" for q, d in QUANTITIES) + ".")
    return rep


def run(out: Path, *, quick: bool = False, progress: bool = False,
        config: RobustnessConfig | None = None) -> Path:
    """Run the Monte Carlo study and write ``report.md``, ``report.html``, ``runs.csv`` and ``results.json``.

    Parameters
    ----------
    out : pathlib.Path
        Output folder (created).
    quick : bool, optional
        CI smoke test (3 samples of 3 s per vehicle and controller).
    progress : bool, optional
        Print one line per vehicle and controller.
    config : RobustnessConfig, optional
        Overrides the default (or quick) configuration.

    Returns
    -------
    pathlib.Path
        ``out/report.md``.
    """
    from ..control.gain_presets import available_gain_presets

    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    cfg = config or (QUICK if quick else FULL)
    samples = draw_samples(cfg.n, cfg.seed)
    compile_first([(kind, "5dof") for _, kind, _ in CONTROLLERS], progress=progress)
    have = set(available_gain_presets())
    controllers = [c for c in CONTROLLERS if c[2] is None or c[2] in have]
    skipped = [c[0] for c in CONTROLLERS if c not in controllers]
    summary: dict[str, dict] = {}
    rows = []
    wall = time.perf_counter()
    for vehicle in cfg.vehicles:
        summary[vehicle] = {}
        for label, kind, preset in controllers:
            t0 = time.perf_counter()
            scs = [sample_scenario(s, vehicle, kind, preset, cfg.duration, cfg.dt) for s in samples]
            results = run_batch([prepare(load_scenario(sc)) for sc in scs], trajectories=True, workers=cfg.workers)
            recs = [_record(r, cfg.duration) for r in results]
            for s, rec in zip(samples, recs):
                rows.append({"vehicle": vehicle, "controller": label, **asdict(s), **rec})
            summary[vehicle][label] = summarise(recs)
            if progress:
                s = summary[vehicle][label]
                print(f"{vehicle} / {label}: {s['failed']}/{s['n']} failed ({time.perf_counter() - t0:.1f} s)")
    wall = time.perf_counter() - wall
    import pandas as pd

    df = pd.DataFrame(rows)
    df["eta0"] = df["eta0"].map(lambda e: " ".join(f"{x:.6g}" for x in e))
    df.to_csv(out / "runs.csv", index=False)
    write_json(out / "results.json", (
        {"config": asdict(cfg), "quick": quick, "controllers": controllers, "summary": summary}))
    return _report(out, summary, cfg, quick, wall, skipped).write()


STUDY = StudySpec("robustness", run, "Monte Carlo over +-30 % model error, disturbance amplitude/phase and "
                  "initial state; failure rate by cause and metric quantiles per controller, paper and remus100")
