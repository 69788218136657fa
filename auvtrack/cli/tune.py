"""``auvtrack tune``: tune one controller's gains on a suite's training split (docs/tuning.md)."""
from __future__ import annotations

import click

from ..batch.scheduler import SCHEDULER_TIMEOUT_S
from .common import EXIT_CODES_HELP, EXIT_INTERRUPTED, BadInput, cli, one_line
from .signals import stop_once


@cli.command(epilog=EXIT_CODES_HELP)
@click.option("--controller", required=True, metavar="KIND|FILE.py",
              help="A built-in tracking controller or a plug-in file; its Params declare the gains searched.")
@click.option("--suite", "suite_name", default="auv-track-v1", show_default=True, metavar="NAME",
              help="A shipped suite or a suite TOML file; its [splits.training] seeds are flown.")
@click.option("--budget", type=int, required=True, metavar="TRIALS",
              help="Trials (each flies every run of the training split: budget = trials x training runs).")
@click.option("--out", type=click.Path(file_okay=False), required=True,
              help="Output folder: study.db (resumed when present), the preset, results.json, report.html.")
@click.option("--sampler", type=click.Choice(["tpe", "cmaes"]), default="tpe", show_default=True)
@click.option("--seed", type=click.IntRange(0, 2**31 - 1), default=0, show_default=True, help="Sampler seed.")
@click.option("--workers", type=click.IntRange(1, 256), default=None,
              help="Threads of the batch runner inside a trial [default: every core; 1 with --parallel > 1 or "
                   "--scheduler, whose trials run side by side].")
@click.option("--parallel", type=click.IntRange(1, 256), default=1, show_default=True,
              help="Trials flown at once by local processes adding to the one study (with --scheduler: Dask tasks, "
                   "default one per thread of the cluster).")
@click.option("--scheduler", default=None, metavar="ADDRESS",
              help=f"Add the trials on an existing Dask scheduler, tcp://host:port (probed for {SCHEDULER_TIMEOUT_S:g} s "
                   "first); its workers must reach --out.")
@click.option("--backend", default=None, metavar="NAME", help="Back end of the batch runner (default: simd lanes where the vector math library is in use, "
                   "else threads; the same results).")
@click.option("--no-validate", is_flag=True, help="Do not fly the best gains on the validation split.")
@click.option("--quiet", is_flag=True, help="No progress line, no compile notice or bar, no Optuna log or warnings.")
def tune(controller: str, suite_name: str, budget: int, out: str, sampler: str, seed: int, workers: int | None,
         parallel: int, scheduler: str | None, backend: str | None, no_validate: bool, quiet: bool) -> None:
    """Tune a controller for the suite's vehicle with Optuna; Ctrl-C or SIGTERM keeps the study, run again to resume.

    The kernels the trials fly are compiled (or loaded) before the first trial, with the
    "compiling kernels (first run only, about N s)" notice and a progress bar on a first run.
    """
    from ..benchmark.suite import SuiteError
    from ..tuning import tune as _tune

    stopped = None
    if workers is None and (parallel > 1 or scheduler):
        workers = 1  # one thread per trial flown at once

    def progress(done: int, total: int) -> None:
        if not quiet:
            click.echo(f"trial {done}/{total}", err=True)
        if stopped is not None and stopped():  # a signal whose KeyboardInterrupt was lost: stop here
            raise KeyboardInterrupt

    with stop_once() as stopped:
        try:
            res = _tune(controller, suite_name, trials=budget, out=out, sampler=sampler, seed=seed,
                        validate=not no_validate, workers=workers, backend=backend, parallel=parallel,
                        scheduler=scheduler, progress=progress, compile_bar=not quiet, quiet=quiet)
        except (SuiteError, ValueError) as exc:
            raise BadInput(one_line(exc)) from None
        except KeyboardInterrupt:
            click.echo(f"auvtrack: interrupted; the study in {out} resumes with the same command", err=True)
            raise click.exceptions.Exit(EXIT_INTERRUPTED) from None
    click.echo(f"trials: {res.trials} ({res.complete} complete, {res.pruned} pruned, {res.refused} refused); "
               f"runs: {res.runs}; RK4 steps: {res.steps}; CPU {res.cpu_s:.1f} s; wall {res.wall_s:.1f} s")
    click.echo(f"best training score: {res.best_score:.6g}; validation-split score: {res.validation_score:.6g}")
    for k, p in res.outputs.items():
        click.echo(f"{k}: {p}")
