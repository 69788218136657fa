"""``auvtrack sweep``: parameter sweeps and Monte Carlo studies on Dask."""
from __future__ import annotations

from pathlib import Path

import click

from .common import EXIT_CODES_HELP, EXIT_INTERRUPTED, MAX_WORKERS, BadInput, cli


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
    from ..batch.sweep import parse_memory, run_sweep
    from ..batch.sweep_spec import load_study

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
