"""Command line: ``auvtrack reproduce | run | check | bounds | study | sweep | compare | bench | warmup``.

Bad input (a scenario error, a missing file, an invalid gain, a run over the plan's limits, an
output folder that cannot be written) prints ONE line to stderr and exits with status 2, never a
traceback, and before anything runs.  ``check`` runs exactly the validation of ``run`` (load,
plan, controller set-up), so it refuses the same scenarios with the same message.  A simulation
that fails (divergence, pitch limit, envelope violation) keeps and saves its partial result,
prints the diagnostic and exits 3.  Ctrl-C stops a run within about a second, saves what was
computed with status ``interrupted`` and exits 130; a sweep closes its cluster, keeps its
completed chunks for ``--resume`` and exits 130 (so does ``compare``).  ``auvtrack --help`` lists every command and
these exit codes.
"""
from __future__ import annotations

import inspect
import json
import sys
import warnings
from pathlib import Path

import click

EXIT_BAD_INPUT = 2
EXIT_SIM_FAILED = 3
EXIT_INTERRUPTED = 130
MAX_WORKERS = 256
MAX_REPEAT = 1000
LONG_RUN_STEPS = 1_000_000  # runs this long announce themselves (and that Ctrl-C keeps their result)


class BadInput(click.ClickException):
    """Any user error: shown as one line, exit status 2."""

    exit_code = EXIT_BAD_INPUT

    def show(self, file=None) -> None:  # noqa: D102 - one line, no "Error:" banner
        click.echo(f"auvtrack: error: {self.format_message()}", err=True)


def _load(scenario: str, overrides: tuple[str, ...]):
    from .scenario import load_scenario

    return load_scenario(scenario, list(overrides))


def _prepare(scenario: str, sc):
    """The run's validation after loading: plan and controller set-up (``check`` = ``run`` minus the run)."""
    from .simulation.api import prepare

    try:
        return prepare(sc)
    except ValueError as exc:  # ScenarioError of the plan, or a controller refusing its set-up
        raise BadInput(f"{scenario}: {_one_line(exc)}") from None


def _mib(n: int) -> str:
    return f"{n / 2 ** 20:.3g} MiB"


def _one_line(exc: BaseException) -> str:
    return " ".join(str(exc).split()) or type(exc).__name__


EXIT_CODES = (("0", "success"),
              ("2", "bad input: one line naming the field and the allowed range, no traceback, nothing run"),
              ("3", "a simulation failed (diverged, pitch limit, envelope violated): the diagnostic is printed "
                    "and the partial result kept"),
              ("130", "interrupted (Ctrl-C): a run keeps its partial result, a sweep or a comparison its "
                      "completed chunks"))
EXIT_CODES_HELP = "Exit status: " + "; ".join(f"{code} {text}" for code, text in EXIT_CODES) + "."
COMMAND_ORDER = ("reproduce", "run", "check", "bounds", "study", "sweep", "compare", "bench", "warmup")


def _first_paragraph(text: str | None) -> str:
    return " ".join(inspect.cleandoc(text or "").split("\n\n")[0].split())


class _Group(click.Group):
    """Top-level group: every command with its whole first help paragraph, then the exit codes."""

    def list_commands(self, ctx: click.Context) -> list[str]:
        names = super().list_commands(ctx)
        return [n for n in COMMAND_ORDER if n in names] + [n for n in names if n not in COMMAND_ORDER]

    def format_commands(self, ctx: click.Context, formatter: click.HelpFormatter) -> None:
        rows = [(n, _first_paragraph(c.help)) for n in self.list_commands(ctx)
                if (c := self.get_command(ctx, n)) is not None and not c.hidden]
        with formatter.section("Commands"):
            formatter.write_dl(rows)

    def format_epilog(self, ctx: click.Context, formatter: click.HelpFormatter) -> None:
        with formatter.section("Exit status"):
            formatter.write_dl(list(EXIT_CODES))
        super().format_epilog(ctx, formatter)


@click.group(cls=_Group, context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(package_name="auvtrack")
def cli() -> None:
    """auvtrack: trajectory-tracking control of underactuated AUVs.

    Scenarios are TOML files in which every key has a default (docs/scenarios.md); an empty
    file is the paper's Section 4.  Start with `auvtrack reproduce`.  The first command after
    installing or editing the package compiles the Numba kernels (about a minute, more on a
    loaded machine; cached on disk afterwards); `auvtrack warmup` does that up front.
    """


set_option = click.option("--set", "overrides", multiple=True, metavar="KEY=VALUE",
                          help="Override a scenario key, e.g. --set sim.dt=0.002 (repeatable).")


@cli.command(epilog=EXIT_CODES_HELP)
@click.argument("scenario")
@click.option("--out", default=None, metavar="FOLDER",
              help="Run folder, replaced as a whole if it exists and holds only a run (default: a new "
                   "runs/<name>-<controller>, numbered -2, -3, ... when taken).")
@set_option
@click.option("--mat", is_flag=True, help="Also write trajectory.mat (MATLAB).")
def run(scenario: str, out: str | None, overrides: tuple[str, ...], mat: bool) -> None:
    """Simulate SCENARIO (a TOML file) and write trajectory.csv, run.json and scenario.toml to a run folder.

    Without --out every run gets a new folder runs/<name>-<controller> (then -2, -3, ...), so a
    second run never overwrites the first; the folder is printed.  The folder is checked before
    the simulation starts, and scenario.toml reproduces the run (auvtrack run <folder>/scenario.toml).
    """
    from .simulation.api import SimulationInterrupted, ensure_compiled, run_prepared
    from .simulation.result import FolderError, prepare_run_folder
    from .simulation.run_folder import default_run_folder

    sc = _load(scenario, overrides)
    prep = _prepare(scenario, sc)
    target = Path(out) if out is not None else default_run_folder(sc.name, sc.controller.kind)
    try:  # before the run: an unwritable folder must not cost the simulation
        prepare_run_folder(target)
    except FolderError as exc:
        raise BadInput(f"{'--out' if out is not None else 'run folder'}: {_one_line(exc)}") from None
    for note in prep.notes:
        click.echo(f"warning: {note}", err=True)
    if not sc.controller.kind.startswith("open_loop"):  # a reference the plant cannot fly: say so, fly anyway
        from .plant.feasibility import assess
        if (line := assess(sc).warning()) is not None:
            click.echo(f"warning: {line}", err=True)
    ensure_compiled([prep])  # compile or load the kernel first: Ctrl-C from here on stops the simulation
    if prep.n_steps >= LONG_RUN_STEPS:
        click.echo(f"running {prep.n_steps} RK4 steps (Ctrl-C stops the run and keeps its partial result)", err=True)
    try:
        res = run_prepared(prep)
    except SimulationInterrupted as exc:  # stopped within about a second; write what was computed
        res = exc.result
    try:
        folder = res.save(target, mat=mat or sc.output.mat, overwrite=out is not None)
    except OSError as exc:  # FolderError (the folder changed since the check), a full disk...
        click.echo(f"auvtrack: error: the run folder {target} could not be written: {_one_line(exc)}", err=True)
        raise click.exceptions.Exit(EXIT_SIM_FAILED) from None
    click.echo(f"{res!r}\nwritten: {folder}")
    if res.status == "interrupted":
        click.echo(f"auvtrack: interrupted at t = {res.failure['time']:.6g} s after {res.meta['steps']} of "
                   f"{prep.n_steps} steps; partial result kept in {folder}", err=True)
        raise click.exceptions.Exit(EXIT_INTERRUPTED)
    if not res.ok:
        f = res.failure
        click.echo(f"auvtrack: simulation failed at t = {f['time']:.6g} s: {f['cause']}: {f['detail']}; "
                   f"state {json.dumps(f['state'])}; partial result kept in {folder}", err=True)
        raise click.exceptions.Exit(EXIT_SIM_FAILED)


@cli.command(epilog=EXIT_CODES_HELP)
@click.argument("scenario")
@set_option
def check(scenario: str, overrides: tuple[str, ...]) -> None:
    """Validate SCENARIO and its --set overrides as run would (load, plan, controller set-up), without simulating.

    Warns where Theorem 1's conditions fail, and prints whether the plant can fly the reference
    (trim, surge, tightest turn against the limits; docs/vehicles.md#feasibility).
    """
    from .scenario.plan import plan_run

    sc = _load(scenario, overrides)
    prep = _prepare(scenario, sc)
    for note in prep.notes:
        click.echo(f"warning: {note}", err=True)
    if sc.controller.kind == "fxtntsmc":
        from .control.theory import check_theorem1

        for v in check_theorem1(sc.controller):
            click.echo(f"warning: {v}", err=True)
    plan = plan_run(sc, len(prep.channels))
    click.echo(f"ok: {scenario} ({sc.name}: controller {sc.controller.kind}, "
               f"{sc.sim.duration:g} s at dt {sc.sim.dt:g} s: {plan.n_steps} steps, {plan.log_rows} logged rows, "
               f"~{_mib(plan.memory_bytes)})")
    from .plant.feasibility import assess

    click.echo(assess(sc).summary())


@cli.command()
@click.argument("scenario")
@set_option
@click.option("--gamma1", default=0.5, show_default=True, help="Lemma 1 constant in (0, 1).")
@click.option("--g1", default=0.5, show_default=True, help="Tuning constant of eq. (45) in (0, 1).")
@click.option("--g2", default=0.5, show_default=True, help="Tuning constant of eq. (50) in (0, 1).")
@click.option("--json", "as_json", is_flag=True, help="Print JSON instead of text.")
def bounds(scenario: str, overrides: tuple[str, ...], gamma1: float, g1: float, g2: float, as_json: bool) -> None:
    """Print Theorem 1's fixed-time bounds for the FXTNTSMC gains of SCENARIO, and whether they are vacuous."""
    from .control.theory import fixed_time_bounds

    sc = _load(scenario, overrides)
    if sc.controller.kind != "fxtntsmc":
        raise BadInput(f"controller.kind: bounds exist for 'fxtntsmc' only (got {sc.controller.kind!r})")
    b = fixed_time_bounds(sc.controller, gamma1=gamma1, g1=g1, g2=g2, horizon=sc.sim.duration)
    click.echo(json.dumps(b.to_dict(), indent=2) if as_json else b.report())


@cli.command()
@click.option("--controller", "controllers", multiple=True,
              help="Controller kind(s), or plugin:FILE.py (default: every built-in controller).")
@click.option("--repeat", default=7, show_default=True, help="Timed repetitions; the median is reported.")
@click.option("--duration", default=20.0, show_default=True, help="Simulated seconds per repetition.")
@click.option("--all", "run_all", is_flag=True,
              help="Full suite: cold first run and cold warmup (empty cache), every controller, batch runs/s and "
                   "efficiency per back end (simd included), sweep throughput on 1 and 2 Dask workers; "
                   "writes results.{json,md} to --out.")
@click.option("--out", "bench_out", type=click.Path(file_okay=False), default=None,
              help="Folder for the --all results (default: a new folder under ~/.local/share/auvtrack/bench, "
                   "or $XDG_DATA_HOME; never the source tree unless asked, e.g. --out benchmarks).")
@click.option("--plant", type=click.Choice(["5dof", "6dof"]), default="5dof", show_default=True,
              help="Plant model: 5dof (Section 4) or 6dof (each REMUS 100 truth preset, a 1 m/s line).")
def bench(controllers: tuple[str, ...], repeat: int, duration: float, run_all: bool, bench_out: str | None,
          plant: str = "5dof") -> None:
    """Time the compiled closed loop: µs per RK4 step, one JSON line per controller (every built-in by default).

    --all runs the full suite (batch runs/s, Dask sweep throughput) and writes results.json and
    results.md to --out (default: a new user folder; the working tree is left unchanged).
    """
    if not 1 <= repeat <= MAX_REPEAT:
        raise BadInput(f"--repeat: must be in [1, {MAX_REPEAT}] (a median needs at least one timing) (got {repeat})")
    if not duration > 0:
        raise BadInput(f"--duration: must be > 0 s (got {duration:g})")

    if run_all:
        from .runner.bench import bench_all

        doc = bench_all(repeat=repeat, out=Path(bench_out) if bench_out else None, progress=True)
        folder = doc.pop("out")
        click.echo(json.dumps(doc, indent=2))
        click.echo(f"written: {folder / 'results.json'}, {folder / 'results.md'}")
        return
    from .runner.bench import bench_plant, bench_singles, builtin_controllers

    if plant != "5dof":  # issue 11: the 6-DOF truths, one line per (controller, preset)
        for row in bench_plant(controllers or ("ftsmc", "fxtntsmc"), plant, repeat=repeat, duration=duration):
            click.echo(json.dumps(row))
        return
    for row in bench_singles(controllers or builtin_controllers(), repeat=repeat, duration=duration):
        click.echo(json.dumps(row))


@cli.command()
@click.option("--controller", "controllers", multiple=True, help="Controller kind(s) (default: every one).")
@click.option("--plant", "plants", multiple=True, help="Plant model(s) (default: every one).")
@click.option("--simd", is_flag=True, help="Also compile the SIMD batch kernels (`--backend simd`; a few times longer).")
def warmup(controllers: tuple[str, ...], plants: tuple[str, ...], simd: bool) -> None:
    """Compile every kernel (each controller on each plant) once, in parallel; later runs load them.

    The first command after installing or editing the package compiles the kernels it needs
    (about a minute, more on a loaded machine); warmup does it for every command up front.
    """
    from .runner.bench import warmup as _warmup

    click.echo(json.dumps(_warmup(controllers, plants, progress=True, simd=simd)))


@cli.command(epilog=EXIT_CODES_HELP)
@click.argument("study")
@click.option("--out", default=None, metavar="FOLDER", help="Output folder (default sweeps/<name>).")
@click.option("--workers", type=int, default=None, help="Worker processes of the local Dask cluster (default: cores).")
@click.option("--worker-memory", default="1GiB", show_default=True, metavar="SIZE",
              help="Memory limit of each local worker (e.g. 2GiB); a sample that would not fit is recorded as failed.")
@click.option("--scheduler", default=None, metavar="ADDRESS", help="Use an existing Dask scheduler, tcp://host:port.")
@click.option("--resume", is_flag=True, help="Finish an interrupted sweep in --out (completed chunks are kept).")
@click.option("--max-chunks", type=int, default=None, hidden=True, help="Stop after this many chunks (testing).")
@click.option("--quiet", is_flag=True, help="No progress bar.")
def sweep(study: str, out: str | None, workers: int | None, worker_memory: str, scheduler: str | None, resume: bool,
          max_chunks: int | None, quiet: bool) -> None:
    """Run the parameter sweep / Monte Carlo study STUDY (a TOML file) on Dask: Parquet rows, quantiles, --resume.

    The study format is docs/sweeps.md; scenarios/sweep_example.toml is an example.
    """
    from .runner.sweep import parse_memory, run_sweep
    from .runner.sweep_schema import load_study

    if workers is not None and scheduler:
        raise BadInput("--workers and --scheduler exclude each other (the scheduler's cluster has its workers)")
    if workers is not None and not 1 <= workers <= MAX_WORKERS:
        raise BadInput(f"--workers: must be in [1, {MAX_WORKERS}] (got {workers})")
    parse_memory(worker_memory)
    spec = load_study(study)
    folder = Path(out) if out else Path("sweeps") / spec.study.name
    if folder.is_symlink() or (folder.exists() and not folder.is_dir()):
        raise BadInput(f"--out: {folder}: is {'a symbolic link' if folder.is_symlink() else 'a file'}, not a folder")

    def _stop(signum, frame):  # SIGTERM / SIGINT: stop cleanly (cluster closed, chunks kept for --resume)
        raise KeyboardInterrupt

    import signal

    import threading

    main_thread = threading.current_thread() is threading.main_thread()  # signals are the main thread's
    handlers = {sig: signal.signal(sig, _stop) for sig in (signal.SIGTERM, signal.SIGINT)} if main_thread else {}
    try:
        res = run_sweep(spec, folder, workers=workers, scheduler=scheduler, resume=resume, max_chunks=max_chunks,
                        progress=not quiet, memory_limit=worker_memory)
    except KeyboardInterrupt:
        click.echo(f"auvtrack: sweep interrupted (the cluster is closed, completed chunks are kept); finish with: "
                   f"auvtrack sweep {study} --out {folder} --resume", err=True)
        raise click.exceptions.Exit(EXIT_INTERRUPTED) from None
    finally:
        for sig, handler in handlers.items():
            signal.signal(sig, handler)
    if res.complete:
        click.echo((folder / "summary.md").read_text())
        click.echo(f"written: {folder / 'results.parquet'}, {folder / 'summary.json'}, {folder / 'summary.md'}")
    else:
        click.echo(f"stopped after {res.chunks_run} chunks; finish with: auvtrack sweep {study} --out {folder} --resume")


def _split_names(values: tuple[str, ...]) -> list[str]:
    return [n.strip() for v in values for n in v.split(",") if n.strip()]


@cli.command(epilog=EXIT_CODES_HELP)
@click.option("--suite", "suite_name", default="auv-track-v1", show_default=True, metavar="NAME",
              help="A shipped suite (auvtrack/data/benchmarks/NAME.toml) or a suite TOML file.")
@click.option("--controllers", "controllers", multiple=True, metavar="KIND[,KIND...]",
              help="Built-in controllers to compare (repeatable or comma-separated; default: every registered "
                   "tracking controller).")
@click.option("--plugin", "plugins", multiple=True, type=click.Path(dir_okay=False), metavar="FILE.py",
              help="Add a plug-in controller file to the comparison (repeatable); it enters under its file name.")
@click.option("--quick", is_flag=True, help="CI-sized: every controller, task and tier, few seeds, short runs.")
@click.option("--out", type=click.Path(file_okay=False), default=None,
              help="Output folder (default compare/<suite>, compare/<suite>-quick with --quick).")
@click.option("--scheduler", default=None, metavar="ADDRESS", help="Run on an existing Dask scheduler, tcp://host:port.")
@click.option("--workers", type=int, default=None, help="Local threads (default: every core).")
@click.option("--backend", default=None, metavar="NAME",
              help="Back end of the batch runner (auvtrack.runner.batch.BACKENDS; default: its default).")
@click.option("--resume", is_flag=True, help="Finish an interrupted comparison in --out (completed chunks are kept).")
@click.option("--max-chunks", type=int, default=None, hidden=True, help="Stop after this many chunks (testing).")
@click.option("--quiet", is_flag=True, help="No progress bar.")
def compare(suite_name: str, controllers: tuple[str, ...], plugins: tuple[str, ...], quick: bool, out: str | None,
            scheduler: str | None, workers: int | None, backend: str | None, resume: bool, max_chunks: int | None,
            quiet: bool) -> None:
    """Benchmark the controllers over a suite's tasks x tiers x seeds; write report.md/.html, results.json, runs.parquet.

    Every registered tracking controller runs with its tuned gain preset ({kind}_tuned) or, without one, its
    defaults; every controller sees the same seeds. Ranks, intervals and tests: docs/benchmark.md.
    """
    from .runner.batch import BatchInterrupted
    from .runner.compare import CompareError
    from .studies.benchmark import compare as _compare, default_out
    from .studies.suite import SuiteError, load_suite

    if workers is not None and scheduler:
        raise BadInput("--workers and --scheduler exclude each other (the scheduler's cluster has its workers)")
    if workers is not None and workers < 1:
        raise BadInput(f"--workers: must be >= 1 (got {workers})")
    try:
        suite = load_suite(suite_name)
    except SuiteError as exc:
        raise BadInput(_one_line(exc)) from None
    if quick:
        suite = suite.quick_variant()
    folder = Path(out) if out else default_out(suite)

    def _stop(signum, frame):  # SIGTERM as Ctrl-C: stop cleanly, the finished chunks stay for --resume
        raise KeyboardInterrupt

    import signal

    previous = signal.signal(signal.SIGTERM, _stop)
    try:
        res = _compare(suite, controllers=_split_names(controllers) or None, plugins=list(plugins), out=folder,
                       scheduler=scheduler, workers=workers, backend=backend, resume=resume, max_chunks=max_chunks,
                       progress=not quiet)
    except (SuiteError, CompareError) as exc:
        raise BadInput(_one_line(exc)) from None
    except (BatchInterrupted, KeyboardInterrupt):
        click.echo(f"auvtrack: interrupted; the finished chunks are kept: auvtrack compare --suite {suite_name}"
                   f"{' --quick' if quick else ''} --out {folder} --resume", err=True)
        raise click.exceptions.Exit(130)
    finally:
        signal.signal(signal.SIGTERM, previous)
    if not res.complete:
        click.echo(f"stopped after {res.execution.chunks_run} chunks; finish with: auvtrack compare --suite "
                   f"{suite_name}{' --quick' if quick else ''} --out {folder} --resume")
        return
    click.echo(f"runs: {res.execution.runs} in {res.execution.seconds:.1f} s (+ {res.analysis_seconds:.1f} s "
               f"statistics and report)\nreport: {res.report}\nwritten: {folder / 'results.json'}, "
               f"{folder / 'runs.parquet'}")


@cli.command()
@click.option("--out", type=click.Path(file_okay=False), default="reproduce", show_default=True,
              help="Output folder (overwritten).")
@click.option("--quick", is_flag=True, help="Short horizon (smoke test).")
def reproduce(out: str, quick: bool) -> None:
    """Reproduce the paper's Section 4: both controllers, Figures 3-8, metrics and a verdict on each claim.

    Writes the run folders, figures/, metrics.json, summary.md and report.html (one
    self-contained page with every figure) to --out.
    """
    from .studies.reproduce import reproduce as _reproduce

    summary = _reproduce(Path(out), quick=quick, progress=True)
    click.echo(summary)
    click.echo(f"written: {Path(out) / 'summary.md'}, {Path(out) / 'report.html'}")


class _StudyCommand(click.Command):
    """``auvtrack study``: its ``--help`` lists the registered studies with their summaries."""

    def format_epilog(self, ctx: click.Context, formatter: click.HelpFormatter) -> None:
        from .studies.registry import all_studies

        with formatter.section("Studies"):
            formatter.write_dl([(n, s.summary) for n, s in sorted(all_studies().items())])
        super().format_epilog(ctx, formatter)


@cli.command(cls=_StudyCommand)
@click.argument("name")
@click.option("--out", type=click.Path(file_okay=False), default=None, help="Output folder (default studies/<NAME>).")
@click.option("--quick", is_flag=True, help="CI-sized run (seconds instead of minutes).")
@click.option("--pulse", default=None, metavar="F1,F2,F3,F4,F5",
              help="ablation: one pulse direction (N, N, N, N m, N m per unit amplitude) instead of the defaults.")
@click.option("--pulse-start", "pulse_start", type=float, default=None, metavar="T",
              help="ablation: pulse onset in s (default 20; the run lasts until T + 20 s).")
def study(name: str, out: str | None, quick: bool, pulse: str | None, pulse_start: float | None) -> None:
    """Run study NAME and write report.md, report.html, results.json and figures/ (NAME 'list': list them)."""
    from .studies.registry import all_studies, get_study

    if name == "list":
        for n, spec in sorted(all_studies().items()):
            click.echo(f"{n}: {spec.summary}")
        return
    try:
        spec = get_study(name)
    except KeyError as e:
        raise BadInput(str(e.args[0])) from None
    options = {k: v for k, v in (("pulse", pulse), ("pulse_start", pulse_start)) if v is not None}
    for k in options:
        if k not in spec.options:
            raise BadInput(f"--{k.replace('_', '-')}: not an option of study {name!r}")
    report = spec.run(Path(out) if out else Path("studies") / name, quick=quick, progress=True, **options)
    html = report.with_suffix(".html")
    click.echo(f"report: {report}" + (f", {html}" if html.exists() else ""))


def main(argv: list[str] | None = None) -> int:
    """Entry point of the ``auvtrack`` console script; returns the exit status."""
    from .scenario import ScenarioError

    warnings.simplefilter("default")
    try:
        rv = cli.main(args=argv, prog_name="auvtrack", standalone_mode=False)
    except click.exceptions.Exit as e:
        return e.exit_code
    except click.UsageError as e:  # one line too, with where to look
        where = f" (see '{e.ctx.command_path} --help')" if e.ctx is not None else ""
        click.echo(f"auvtrack: error: {_one_line(e.format_message())}{where}", err=True)
        return EXIT_BAD_INPUT
    except click.ClickException as e:
        e.show()
        return e.exit_code
    except click.exceptions.Abort:  # Ctrl-C outside a simulation (loading, compiling, saving)
        click.echo("auvtrack: interrupted", err=True)
        return EXIT_INTERRUPTED
    except (ScenarioError, ValueError, KeyError, OSError) as e:
        click.echo(f"auvtrack: error: {_one_line(e)}", err=True)
        return EXIT_BAD_INPUT
    # without standalone mode, click returns the code of a raised ``Exit`` instead of exiting
    return rv if isinstance(rv, int) else 0


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
