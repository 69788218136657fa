"""``auvtrack sweep``: parameter sweeps and Monte Carlo studies on Dask."""
from __future__ import annotations

import shlex
from pathlib import Path

import click

from ..batch.executor import MAX_WORKERS
from ..batch.scheduler import SCHEDULER_TIMEOUT_S
from .common import EXIT_CODES_HELP, EXIT_INTERRUPTED, BadInput, cli
from .digest import sweep_lines
from .signals import stop_once

DEFAULT_WORKER_MEMORY = "1GiB"  # auvtrack.batch.sweep.DEFAULT_WORKER_MEMORY (not imported: --help stays fast)


def _resume_command(study: str, folder: Path, workers: int | None, worker_memory: str, scheduler: str | None) -> str:
    """The command that finishes this sweep (what was given, with ``--resume``), quoted for a shell."""
    args = ["auvtrack", "sweep", study, "--out", str(folder)]
    if scheduler:
        args += ["--scheduler", scheduler]
    if workers is not None:
        args += ["--workers", str(workers)]
    if worker_memory != DEFAULT_WORKER_MEMORY:
        args += ["--worker-memory", worker_memory]
    return shlex.join([*args, "--resume"])


@cli.command(epilog=EXIT_CODES_HELP)
@click.argument("study")
@click.option("--out", default=None, metavar="FOLDER", help="Output folder (default sweeps/<name>); a new or empty "
              "folder, or one of this sweep with --resume.")
@click.option("--workers", type=int, default=None,
              help=f"Worker processes of the local Dask cluster (default: cores; at most {MAX_WORKERS}).")
@click.option("--worker-memory", default=DEFAULT_WORKER_MEMORY, show_default=True, metavar="SIZE",
              help="Memory limit of each local worker (e.g. 2GiB); a sample that would not fit is recorded as failed.")
@click.option("--scheduler", default=None, metavar="ADDRESS",
              help=f"Use an existing Dask scheduler, tcp://host:port (probed for {SCHEDULER_TIMEOUT_S:g} s first).")
@click.option("--resume", is_flag=True, help="Finish an interrupted sweep in --out: completed chunks are verified "
              "(fingerprint, content hash) and kept; bad ones are named and recomputed.")
@click.option("--max-chunks", type=int, default=None, hidden=True, help="Stop after this many chunks (testing).")
@click.option("--quiet", is_flag=True, help="No progress bar, no compile notice or bar.")
def sweep(study: str, out: str | None, workers: int | None, worker_memory: str, scheduler: str | None, resume: bool,
          max_chunks: int | None, quiet: bool) -> None:
    """Run the parameter sweep / Monte Carlo study STUDY (a TOML file) on Dask: Parquet rows, quantiles, --resume.

    The study format, its [limits] and the output folder are described in docs/sweeps.md;
    scenarios/sweep_example.toml is an example.
    """
    from ..batch.executor import check_workers
    from ..batch.sweep import parse_memory, run_sweep
    from ..batch.sweep_spec import load_study

    if workers is not None and scheduler:
        raise BadInput("--workers and --scheduler exclude each other (the scheduler's cluster has its workers)")
    check_workers(workers, BadInput)
    parse_memory(worker_memory)
    spec = load_study(study)
    folder = Path(out) if out else Path("sweeps") / spec.study.name
    if folder.is_symlink() or (folder.exists() and not folder.is_dir()):
        raise BadInput(f"--out: {folder}: is {'a symbolic link' if folder.is_symlink() else 'a file'}, not a folder")
    again = _resume_command(study, folder, workers, worker_memory, scheduler)
    with stop_once():  # Ctrl-C or SIGTERM: stop once, close the cluster, keep the chunks for --resume
        try:
            res = run_sweep(spec, folder, workers=workers, scheduler=scheduler, resume=resume,
                            max_chunks=max_chunks, progress=not quiet, memory_limit=worker_memory)
        except KeyboardInterrupt:
            click.echo(f"auvtrack: sweep interrupted (the cluster is closed, completed chunks are kept); "
                       f"finish with: {again}", err=True)
            raise click.exceptions.Exit(EXIT_INTERRUPTED) from None
    if res.complete:
        click.echo("\n".join(sweep_lines(res.summary)))
        click.echo(f"written: {folder / 'results.parquet'}, {folder / 'summary.json'}, {folder / 'summary.md'}")
    else:
        click.echo(f"stopped after {res.chunks_run} chunks; finish with: {again}")
