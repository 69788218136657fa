"""``auvtrack compare``: the controller benchmark."""
from __future__ import annotations

import shlex
from pathlib import Path

import click

from ..batch.executor import MAX_WORKERS
from ..batch.scheduler import SCHEDULER_TIMEOUT_S
from ..benchmark.execute import DEFAULT_MAX_RUNS, MAX_RUNS
from .common import EXIT_CODES_HELP, EXIT_INTERRUPTED, BadInput, cli, one_line
from .signals import stop_once


def _split_names(values: tuple[str, ...]) -> list[str]:
    return [n.strip() for v in values for n in v.split(",") if n.strip()]


def resume_command(suite_name: str, quick: bool, controllers: list[str] | None, plugins: tuple[str, ...],
                   folder: Path, backend: str | None, scheduler: str | None, workers: int | None,
                   max_runs: int | None, tune: str | None = None) -> str:
    """The command that finishes a comparison: every option that defines it, ``--out`` and ``--resume``.

    Parameters
    ----------
    suite_name : str
        ``--suite`` as given.
    quick : bool
        ``--quick``.
    controllers : list of str or None
        The controllers named with ``--controllers`` (None: the default, every tracking controller).
    plugins : tuple of str
        ``--plugin`` files as given.
    folder : Path
        The output folder.
    backend, scheduler : str or None
        ``--backend`` (part of the comparison's fingerprint) and ``--scheduler``, when given.
    workers, max_runs : int or None
        ``--workers`` and ``--max-runs``, when given.
    tune : str or None, optional
        ``--tune`` (``"suite"`` for the flag without a value), when given.

    Returns
    -------
    str
        A shell command (arguments quoted) that resumes this comparison in ``folder``.
    """
    args = ["auvtrack", "compare", "--suite", suite_name]
    if quick:
        args.append("--quick")
    if controllers:
        args += ["--controllers", ",".join(controllers)]
    for p in plugins:
        args += ["--plugin", p]
    if backend is not None:
        args += ["--backend", backend]
    if scheduler:
        args += ["--scheduler", scheduler]
    if workers is not None:
        args += ["--workers", str(workers)]
    if max_runs is not None:
        args += ["--max-runs", str(max_runs)]
    if tune is not None:
        args += ["--tune"] if tune == "suite" else ["--tune", tune]
    return shlex.join([*args, "--out", str(folder), "--resume"])


@cli.command(epilog=EXIT_CODES_HELP)
@click.option("--suite", "suite_name", default="auv-track-v1", show_default=True, metavar="NAME",
              help="A shipped suite (auvtrack/data/benchmarks/NAME.toml) or a suite TOML file.")
@click.option("--controllers", "controllers", multiple=True, metavar="KIND[,KIND...]",
              help="Built-in tracking controllers to compare (repeatable or comma-separated; default: every registered "
                   "tracking controller; open-loop kinds are refused).")
@click.option("--plugin", "plugins", multiple=True, type=click.Path(dir_okay=False), metavar="FILE.py",
              help="Add a plug-in controller file to the comparison (repeatable); it enters under its file name. "
                   "It is imported and checked before anything runs.")
@click.option("--quick", is_flag=True, help="CI-sized: every controller, task and tier, few seeds, short runs.")
@click.option("--out", type=click.Path(file_okay=False), default=None,
              help="Output folder (default compare/<suite>, compare/<suite>-quick with --quick): a new or empty "
                   "folder, or one of this comparison with --resume.")
@click.option("--scheduler", default=None, metavar="ADDRESS",
              help=f"Run on an existing Dask scheduler, tcp://host:port (probed for {SCHEDULER_TIMEOUT_S:g} s first).")
@click.option("--workers", type=int, default=None, help=f"Local threads (default: every core; at most {MAX_WORKERS}).")
@click.option("--backend", default=None, metavar="NAME",
              help="Back end of the batch runner (auvtrack.batch.runner.BACKENDS; default: its default).")
@click.option("--max-runs", type=int, default=None, metavar="N",
              help=f"Refuse a plan of more runs (default {DEFAULT_MAX_RUNS}, at most {MAX_RUNS}): checked before "
                   "anything is planned.")
@click.option("--resume", is_flag=True, help="Finish an interrupted comparison in --out: finished chunks are verified "
              "(fingerprint, content hash) and kept; bad ones are named and recomputed.")
@click.option("--max-chunks", type=int, default=None, hidden=True, help="Stop after this many chunks (testing).")
@click.option("--quiet", is_flag=True, help="No progress bar, no compile notice or bar (as tune and train).")
@click.option("--tune", "tune_budget", is_flag=False, flag_value="suite", default=None, metavar="[TRIALS]",
              help="Tune each --plugin first (auvtrack tune on the suite's training split, in <out>-tune/) at the "
                   "suite's shared budget (its presets' trials) or TRIALS; it enters with its best gains.")
def compare(suite_name: str, controllers: tuple[str, ...], plugins: tuple[str, ...], quick: bool, out: str | None,
            scheduler: str | None, workers: int | None, backend: str | None, max_runs: int | None, resume: bool,
            max_chunks: int | None, quiet: bool, tune_budget: str | None) -> None:
    """Benchmark the controllers over a suite's tasks x tiers x seeds; write report.md/.html, results.json, runs.parquet.

    Every registered tracking controller runs with its tuned gain preset ({kind}_tuned) or, without one, its
    defaults; every controller sees the same seeds. Ranks, intervals and tests: docs/benchmark.md.
    """
    from ..batch.executor import check_workers
    from ..batch.runner import BatchInterrupted
    from ..benchmark.compare import compare as _compare, default_out
    from ..benchmark.execute import CompareError
    from ..benchmark.suite import SuiteError, load_suite

    if workers is not None and scheduler:
        raise BadInput("--workers and --scheduler exclude each other (the scheduler's cluster has its workers)")
    check_workers(workers, BadInput)
    names = _split_names(controllers) if controllers else None
    if names == []:
        raise BadInput(f"--controllers: names no controller (got {', '.join(map(repr, controllers))}); omit it "
                       "to compare every tracking controller")
    try:
        suite = load_suite(suite_name)
    except SuiteError as exc:
        raise BadInput(one_line(exc)) from None
    if quick:
        suite = suite.quick_variant()
    folder = Path(out) if out else default_out(suite)
    again = resume_command(suite_name, quick, names, plugins, folder, backend, scheduler, workers, max_runs,
                           tune_budget)
    with stop_once():  # Ctrl-C or SIGTERM (the command line's handling): the finished chunks stay for --resume
        try:
            entries, tuned_dir = None, None
            if tune_budget is not None:
                from ..tuning.newcomer import tune_folder, tuned_entries

                tuned_dir = tune_folder(folder)
                try:
                    entries = tuned_entries(suite, names, plugins, tune_budget, folder, progress=click.echo,
                                            quiet=quiet)
                except ValueError as exc:  # one line naming --tune (a SuiteError is one too)
                    raise BadInput(one_line(exc)) from None
            res = _compare(suite, controllers=names, plugins=list(plugins), out=folder, scheduler=scheduler,
                           entries=entries, tuned_dir=tuned_dir,
                           workers=workers, backend=backend, resume=resume, max_chunks=max_chunks,
                           max_runs=DEFAULT_MAX_RUNS if max_runs is None else max_runs, progress=not quiet)
        except (SuiteError, CompareError) as exc:
            raise BadInput(one_line(exc)) from None
        except (BatchInterrupted, KeyboardInterrupt):
            click.echo(f"auvtrack: interrupted; the finished chunks are kept: {again}", err=True)
            raise click.exceptions.Exit(EXIT_INTERRUPTED) from None
    if not res.complete:
        click.echo(f"stopped after {res.execution.chunks_run} chunks; finish with: {again}")
        return
    click.echo(f"runs: {res.execution.runs} in {res.execution.seconds:.1f} s (+ {res.analysis_seconds:.1f} s "
               f"statistics and report)\nreport: {res.report}\nwritten: {folder / 'results.json'}, "
               f"{folder / 'runs.parquet'}")
