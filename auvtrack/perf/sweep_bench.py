"""Batch and sweep benchmarks of ``auvtrack bench --all`` (reported figures, never timed tests)."""
from __future__ import annotations

import json
import logging
import os
import statistics
import tempfile
import time
from pathlib import Path

BATCH_RUNS = 48  # a multiple of 2 cores x 8 SIMD lanes, so that no back end idles a core on the last runs
RUN_SECONDS = 20.0
"""Length of the single and batch runs, so that the batch efficiencies divide by runs of the same length (the
first seconds of a Section 4 run cost more per step than the rest: 10 s batch runs against 20 s single runs
understated them).  The single run still records its trajectory and the batch does not, which flatters every
back end's efficiency (the ``serial`` one exceeds 1); :func:`simd_over_serial` has neither bias."""
SWEEP_RUN_SECONDS = 10.0
SWEEP_SAMPLES_PER_KIND = 60

_STUDY = """
name = "bench"
scenario = "paper"
set = ["sim.duration={duration}"]
seed = 1
samples = {samples}
chunk_size = 10
[grid]
"controller.kind" = ["ftsmc", "fxtntsmc"]
[random."uncertainty.D"]
dist = "uniform"
low = 0.0
high = 0.3
"""


def _load() -> float | None:
    """1-minute load average (other processes disturb the parallel figures)."""
    try:
        return round(os.getloadavg()[0], 2)
    except OSError:
        return None


def _preps(kind: str, n: int, duration: float) -> list:
    from ..scenario import load_scenario
    from ..simulation.pipeline import prepare
    from ..scenario import paper_scenario_path

    return [prepare(load_scenario(paper_scenario_path(), {"controller.kind": kind, "sim.duration": duration,
                                                          "seed": i, "uncertainty.D": 0.005 * i}))
            for i in range(n)]


BREAKDOWN = (
    ("engine alone (open_loop, three sines per stage)", {"controller.kind": "open_loop"}),
    ("engine alone, no disturbance", {"controller.kind": "open_loop", "disturbance": []}),
    ("ftsmc", {"controller.kind": "ftsmc"}),
    ("fxtntsmc, no envelope, no RBF", {"envelope.kind": "none", "estimator.kind": "none"}),
    ("fxtntsmc, rigid envelope, no RBF", {"envelope.kind": "rigid", "estimator.kind": "none"}),
    ("fxtntsmc, proactive envelope, no RBF", {"estimator.kind": "none"}),
    ("fxtntsmc, no envelope, RBF (7 neurons)", {"envelope.kind": "none"}),
    ("fxtntsmc, proactive envelope, RBF (Section 4)", {}),
    ("fxtntsmc Section 4, controller sampled at 100 Hz", {"sim.control_rate": 100.0}),
)


def bench_breakdown(*, repeat: int = 7, duration: float = 5.0) -> list[dict]:
    """Where the time of one RK4 step goes: CPU µs per step of Section 4 variants (metrics only)."""
    from ..scenario import load_scenario
    from ..simulation.pipeline import prepare
    from ..batch.runner import run_metrics
    from ..scenario import paper_scenario_path

    preps = [prepare(load_scenario(paper_scenario_path(), {"sim.duration": duration, **ov})) for _, ov in BREAKDOWN]
    for prep in preps:
        run_metrics(prep)
    cpu: list[list[float]] = [[] for _ in preps]
    for _ in range(repeat):  # interleaved, so that a slow spell of the machine hits every variant
        for prep, c in zip(preps, cpu):
            c0 = time.thread_time()
            run_metrics(prep)
            c.append(time.thread_time() - c0)
    return [{"variant": label, "overrides": ov,
             "cpu_us_per_step": round(1e6 * statistics.median(c) / int(prep.si[0]), 3)}
            for (label, ov), prep, c in zip(BREAKDOWN, preps, cpu)]


def bench_batch(*, repeat: int = 5, runs: int = BATCH_RUNS, duration: float = RUN_SECONDS) -> list[dict]:
    """Runs per second of the batch runner for each controller and back end (metrics only).

    Also reports the Python-side preparation time per run (scenario validation and packing),
    which is not parallelised by the thread back ends.
    """
    from ..batch.runner import default_workers, run_batch

    kinds, backends = ("ftsmc", "fxtntsmc"), ("serial", "threads", "simd", "prange")
    preps, prep_ms = {}, {}
    for kind in kinds:
        _preps(kind, 2, duration)  # first call pays imports and one-off caches
        t0 = time.perf_counter()
        preps[kind] = _preps(kind, runs, duration)
        prep_ms[kind] = 1e3 * (time.perf_counter() - t0) / runs
        for backend in ("prange", "serial", "threads", "simd"):  # warm (and compile); prange first (see below)
            run_batch(preps[kind][:2], backend=backend)
    rates: dict[tuple[str, str], list[float]] = {(k, b): [] for k in kinds for b in backends}
    cpu: dict[tuple[str, str], list[float]] = {(k, b): [] for k in kinds for b in backends}
    # controllers and the serial, thread-pool and SIMD back ends interleaved (a slow spell of the
    # machine hits them alike); prange in a block of its own, last: after a prange call the
    # OpenMP layer's threads keep spinning for a while and would steal the core from a serial
    # or thread-pool run that followed at once
    for block in (("serial", "threads", "simd"), ("prange",)):
        for _ in range(repeat):
            for backend in block:
                for kind in kinds:
                    t0, c0 = time.perf_counter(), time.process_time()
                    run_batch(preps[kind], backend=backend)
                    rates[(kind, backend)].append(runs / (time.perf_counter() - t0))
                    cpu[(kind, backend)].append((time.process_time() - c0) / runs)
    return [{"controller": kind, "backend": backend, "runs": runs, "run_seconds": duration,
             "runs_per_s": round(statistics.median(r), 2), "max_runs_per_s": round(max(r), 2),
             "cpu_ms_per_run": round(1e3 * statistics.median(cpu[(kind, backend)]), 3),
             "prepare_ms_per_run": round(prep_ms[kind], 3), "cores": default_workers(), "repeat": repeat,
             "load_avg_1min": _load()} for (kind, backend), r in rates.items()]


def bench_sweep(*, repeat: int = 3, workers: tuple[int, ...] = (1, 2), duration: float = SWEEP_RUN_SECONDS,
                samples: int = SWEEP_SAMPLES_PER_KIND) -> list[dict]:
    """Samples per second of ``auvtrack sweep`` on LocalClusters of 1 and 2 worker processes.

    The clusters run side by side and their repetitions alternate, so a change in the machine's
    load affects both alike; the parallel efficiency is the median over repetitions of
    rate(n) / (n rate(1)).  Cluster start-up and worker warm-up are excluded (paid once per
    sweep); the time covers submitting, computing and writing every chunk.  The workers log
    CRITICAL only: a worker that heartbeats while its cluster shuts down logs a 30-line ERROR
    traceback (``Failed to communicate with scheduler during heartbeat``) that says nothing
    about the benchmark; a failing task still raises in :func:`~auvtrack.batch.sweep.run_sweep`.
    """
    from contextlib import ExitStack

    from dask.distributed import Client, LocalCluster

    from ..batch.sweep import run_sweep
    from ..batch.sweep_spec import load_study

    with tempfile.TemporaryDirectory() as tmp, ExitStack() as stack:
        study = Path(tmp) / "study.toml"
        study.write_text(_STUDY.format(duration=duration, samples=samples))
        spec = load_study(study)
        clients = {}
        for n in workers:
            cluster = stack.enter_context(LocalCluster(n_workers=n, threads_per_worker=1, processes=True,
                                                       dashboard_address=":0", memory_limit="1GiB",
                                                       silence_logs=logging.CRITICAL))
            clients[n] = stack.enter_context(Client(cluster))
            run_sweep(spec, Path(tmp) / f"warm-{n}", client=clients[n], progress=False, max_chunks=1)
        rates: dict[int, list[float]] = {n: [] for n in workers}
        for r in range(repeat):
            for n in workers:
                res = run_sweep(spec, Path(tmp) / f"w{n}-{r}", client=clients[n], progress=False)
                rates[n].append(spec.n_samples / res.seconds)
        base = workers[0]
        rows = []
        for n in workers:
            eff = [rn / (n / base * r1) for rn, r1 in zip(rates[n], rates[base])]
            rows.append({"workers": n, "samples": spec.n_samples, "run_seconds": duration,
                         "samples_per_s": round(statistics.median(rates[n]), 2),
                         "max_samples_per_s": round(max(rates[n]), 2), "repeat": repeat,
                         "parallel_efficiency": round(statistics.median(eff), 3), "load_avg_1min": _load()})
    return rows


def batch_efficiency(row: dict, us_per_step: float, dt: float = 0.001) -> float:
    """Runs per second per core x RK4 steps per run x the single run's seconds per step.

    1 means a core does in the batch what it does in single runs; a SIMD back end that runs L
    runs per register can exceed 1 (at most about L).
    """
    steps = round(row["run_seconds"] / dt)
    return row["runs_per_s"] / row["cores"] * steps * us_per_step * 1e-6


def batch_cpu_efficiency(row: dict, cpu_us_per_step: float, dt: float = 0.001) -> float:
    """The single run's CPU time per run over the batch's CPU time per run (all threads of the process).

    :func:`batch_efficiency` from CPU time instead of wall time: less disturbed by other processes
    on a shared machine (it cannot see two threads slowing each other down on one core).
    """
    steps = round(row["run_seconds"] / dt)
    return steps * cpu_us_per_step * 1e-3 / row["cpu_ms_per_run"]


def simd_over_serial(batch: dict, kind: str) -> float:
    """CPU time per run of the ``serial`` back end over that of ``simd``, on the same metrics-only runs.

    ``batch`` maps (controller, back end) to a :func:`bench_batch` row.  Unlike the efficiencies,
    which divide by the single run (that also records a trajectory), this compares like with like.
    """
    return batch[(kind, "serial")]["cpu_ms_per_run"] / batch[(kind, "simd")]["cpu_ms_per_run"]


def bench_cold_start(*, duration: float = 1.0) -> dict:
    """Wall time of ``auvtrack run`` of the Section 4 scenario in a new process with an empty kernel cache.

    What a user waits for on a fresh install: imports, scenario validation, compiling the one
    kernel the run needs (and nothing else), the run, writing its folder.  Also reports the kernel
    compile time the run recorded (its cache marker).
    """
    import subprocess
    import sys

    from ..scenario import paper_scenario_path

    with tempfile.TemporaryDirectory() as tmp:
        env = {**os.environ, "AUVTRACK_CACHE_DIR": str(Path(tmp) / "cache")}
        load = _load()
        t0 = time.perf_counter()
        proc = subprocess.run([sys.executable, "-m", "auvtrack.cli", "run", str(paper_scenario_path()), "--set",
                               f"sim.duration={duration}", "--out", str(Path(tmp) / "run")], env=env, cwd=tmp,
                              capture_output=True, text=True)
        wall = time.perf_counter() - t0
        markers = [json.loads(m.read_text()) for m in (Path(tmp) / "cache").glob("*/kernels/*.compiled.json")]
    if proc.returncode != 0:
        raise RuntimeError(f"cold run failed: {proc.stderr.strip()[-500:]}")
    return {"seconds": round(wall, 2), "compile_seconds": round(sum(m["seconds"] for m in markers), 2),
            "kernels_compiled": [m["kernel"] for m in markers], "run_seconds": duration, "load_avg_1min": load}


def bench_cold_warmup() -> dict:
    """Wall time of ``auvtrack warmup`` (every built-in controller on every plant it runs on) with an empty cache."""
    import subprocess
    import sys

    with tempfile.TemporaryDirectory() as tmp:
        env = {**os.environ, "AUVTRACK_CACHE_DIR": str(Path(tmp) / "cache")}
        load = _load()
        t0 = time.perf_counter()
        proc = subprocess.run([sys.executable, "-m", "auvtrack.cli", "warmup"], env=env, cwd=tmp,
                              capture_output=True, text=True)
        wall = time.perf_counter() - t0
    if proc.returncode != 0:
        raise RuntimeError(f"cold warmup failed: {proc.stderr.strip()[-500:]}")
    doc = json.loads(proc.stdout.strip().splitlines()[-1])
    return {"seconds": round(wall, 2), "kernels": len(doc["kernels"]), "load_avg_1min": load}


def write_results(doc: dict, out: Path) -> None:
    """Write ``results.json`` and ``results.md`` (medians and ratios) into ``out``."""
    import datetime

    out.mkdir(parents=True, exist_ok=True)
    doc = {"date": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="minutes"), **doc}
    (out / "results.json").write_text(json.dumps(doc, indent=2))
    m = doc["machine"]
    single = {r["controller"]: r for r in doc["single"]}
    batch = {(r["controller"], r["backend"]): r for r in doc["batch"]}
    lines = ["# Benchmark results", "",
             f"Measured {doc['date']} with `auvtrack bench --all` on {m['cpu']}, {m['cores']} cores, "
             f"Python {m['python']}, Numba {m['numba']}, vector math {m.get('vector_math', 'scalar')} "
             "(`auvtrack.jit.vecmath`); "
             f"load average at the start {m['load_avg_1_5_15']} "
             "(a shared, noisy machine: medians of "
             f"{doc['repeat']} repetitions, {3 * doc['repeat']} for the single runs, taken round-robin over the "
             "rows of each table so that a slow spell of the machine hits every row alike (the batch's prange rows in "
             "a block of their own, after the others); the CPU-time column "
             "is less sensitive to other processes).", ""]
    load = m.get("load_avg_1_5_15") or [0.0]
    if load[0] > 0.5 * (m.get("cores") or 1):
        lines += ["**The machine was not idle when the suite started** (1-minute load average above half the "
                  "cores): other processes may have competed for the cores, inflating wall times and lowering "
                  "the parallel figures (threads, prange, 2 workers); see the `load after` columns.", ""]
    lines += [
             f"## Single run (Section 4, {doc['single'][0]['steps'] / 1000:g} s at dt = 1 ms, controller at every RK4 "
             "stage, one core)", "",
             "| controller | median wall µs / RK4 step | min wall µs / step | median CPU µs / step |",
             "|---|---|---|---|"]
    lines += [f"| {r['controller']} | {r['us_per_step']:.2f} | {r['min_us_per_step']:.2f} | "
              f"{r['cpu_us_per_step']:.2f} |" for r in doc["single"]]
    lines += ["", f"FXTNTSMC / FTSMC: {single['fxtntsmc']['cpu_us_per_step'] / single['ftsmc']['cpu_us_per_step']:.2f} "
              f"(CPU time); open_loop is the engine alone (plant, reference, disturbance, metrics) plus three sines.",
              ""]
    lines += [f"{k} as a plug-in (the module copied to a file, `controller.kind = \"plugin\"`) / built-in: "
              f"{single[f'{k} (plug-in copy)']['cpu_us_per_step'] / single[k]['cpu_us_per_step']:.2f} (CPU time)."
              for k in ("ftsmc", "fxtntsmc") if f"{k} (plug-in copy)" in single and k in single]
    lines += [""] if any("(plug-in copy)" in k for k in single) else []
    if doc.get("breakdown"):
        lines += ["## Where the time goes (median CPU µs per RK4 step, metrics only, 5 s runs)", "",
                  "| variant | CPU µs / step |", "|---|---|"]
        lines += [f"| {r['variant']} | {r['cpu_us_per_step']:.2f} |" for r in doc["breakdown"]]
        lines += [""]
    if doc.get("cold"):
        c, w = doc["cold"], doc.get("cold_warmup")
        lines += ["## Time to the first result (empty kernel cache, new process)", "",
                  "| what | wall s | load before |", "|---|---|---|",
                  f"| `auvtrack run` Section 4 ({c['run_seconds']:g} s), compiling {', '.join(c['kernels_compiled'])} "
                  f"({c['compile_seconds']:.1f} s of it) | {c['seconds']:.1f} | {c['load_avg_1min']} |"]
        if w:
            lines += [f"| `auvtrack warmup`: {w['kernels']} kernels (every built-in controller on every plant it runs "
                      "on, one per 6-DOF preset module) | "
                      f"{w['seconds']:.1f} | {w['load_avg_1min']} |"]
        lines += [""]
    lines += [f"## Batch runner (metrics only, {doc['batch'][0]['run_seconds']:g} s runs at dt = 1 ms)", "",
              "Efficiency = runs / s per core x steps per run x the single run's wall µs per step (table above, "
              "runs of the same length): 1 "
              "is a core doing in the batch what it does in single runs; `simd` runs several simulations in the "
              "lanes of one SIMD register.", "",
              "| controller | back end | runs / s (median) | best | efficiency | CPU ms / run | CPU efficiency | "
              "prepare ms / run (serial Python) | load after |",
              "|---|---|---|---|---|---|---|---|---|"]
    lines += [f"| {r['controller']} | {r['backend']} | {r['runs_per_s']:.1f} | {r['max_runs_per_s']:.1f} | "
              f"{batch_efficiency(r, single[r['controller']]['us_per_step']):.2f} | "
              + (f"{r['cpu_ms_per_run']:.2f} | "
                 f"{batch_cpu_efficiency(r, single[r['controller']]['cpu_us_per_step']):.2f} | "
                 if "cpu_ms_per_run" in r else "| | ")
              + f"{r['prepare_ms_per_run']:.2f} | {r['load_avg_1min']} |" for r in doc["batch"]]
    lines += ["", "CPU efficiency: the single run's CPU time per run (table above) over the batch's "
              "process CPU time per run; unlike the wall-time efficiency it does not drop when other processes "
              "take the cores.  The single run also records its trajectory, which the batch does not; like with "
              "like, the `serial` back end's CPU time per run over the `simd` back end's on the same runs is "
              + ", ".join(f"{k} {simd_over_serial(batch, k):.2f}" for k in sorted({r['controller'] for r in doc['batch']}))
              + "."]
    lines += ["", "## Sweep on Dask distributed (LocalCluster, processes, 1 thread each)", "",
              f"{doc['sweep'][0]['samples']} samples of {doc['sweep'][0]['run_seconds']:g} s (half FTSMC, half "
              "FXTNTSMC, chunks of 10), including per-sample scenario validation and preparation and the "
              "Parquet writes; cluster start-up and warm-up excluded.", "",
              "| workers | samples / s (median) | best | parallel efficiency (median of paired runs) | load after |",
              "|---|---|---|---|---|"]
    lines += [f"| {r['workers']} | {r['samples_per_s']:.1f} | {r['max_samples_per_s']:.1f} | "
              f"{r['parallel_efficiency']:.2f} | {r['load_avg_1min']} |" for r in doc["sweep"]]
    lines += ["", "`load after` is the 1-minute load average right after the row was measured; it includes this "
              "benchmark's own busy cores (up to 2 for the parallel rows), so values well above that mean other "
              "processes were competing for the 2 cores and the row understates the throughput."]
    (out / "results.md").write_text("\n".join(lines) + "\n")
