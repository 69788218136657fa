"""``auvtrack compare``: the controller benchmark."""
from __future__ import annotations

from pathlib import Path

import click

from .common import EXIT_CODES_HELP, BadInput, cli, one_line


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
              help="Back end of the batch runner (auvtrack.batch.runner.BACKENDS; default: its default).")
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
    from ..batch.runner import BatchInterrupted
    from ..benchmark.execute import CompareError
    from ..benchmark.compare import compare as _compare, default_out
    from ..benchmark.suite import SuiteError, load_suite

    if workers is not None and scheduler:
        raise BadInput("--workers and --scheduler exclude each other (the scheduler's cluster has its workers)")
    if workers is not None and workers < 1:
        raise BadInput(f"--workers: must be >= 1 (got {workers})")
    try:
        suite = load_suite(suite_name)
    except SuiteError as exc:
        raise BadInput(one_line(exc)) from None
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
        raise BadInput(one_line(exc)) from None
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
