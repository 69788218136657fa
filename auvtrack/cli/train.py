"""``auvtrack train``: train a linear policy by augmented random search on a suite's training split (docs/gym.md)."""
from __future__ import annotations

import click

from .common import EXIT_CODES_HELP, EXIT_INTERRUPTED, BadInput, cli, one_line
from .signals import stop_once

QUICK_ITERATIONS, ITERATIONS = 8, 50


@cli.command(epilog=EXIT_CODES_HELP)
@click.option("--suite", "suite_name", default="auv-track-v2", show_default=True, metavar="NAME|FILE",
              help="A shipped suite or a suite TOML file; [splits.training] seeds train, [splits.validation] judge.")
@click.option("--tier", default=None, help="The tier flown (default: the training split's first).")
@click.option("--task", "tasks", multiple=True, help="Task(s) flown (default: every task of the training split).")
@click.option("--out", type=click.Path(file_okay=False), required=True,
              help="Output folder: policy.npz, curve.csv, curve.png, checkpoint.npz (resumed when present).")
@click.option("--iterations", type=int, default=None,
              help=f"ARS iterations, the budget [default: {ITERATIONS}; --quick: {QUICK_ITERATIONS}].")
@click.option("--directions", type=int, default=8, show_default=True, help="Random directions per iteration.")
@click.option("--top", type=int, default=4, show_default=True, help="Best directions kept per iteration.")
@click.option("--step-size", type=float, default=0.02, show_default=True, help="ARS step size alpha.")
@click.option("--noise", type=float, default=0.03, show_default=True, help="Exploration standard deviation nu.")
@click.option("--seeds-per-iteration", type=int, default=2, show_default=True,
              help="Training seed indices each direction flies per iteration.")
@click.option("--eval-every", type=int, default=5, show_default=True,
              help="Iterations between held-out (validation-split) evaluations.")
@click.option("--substeps", type=int, default=10, show_default=True, help="RK4 steps per control step.")
@click.option("--duration", type=float, default=None, help="Episode length in s (default: the task's).")
@click.option("--quick", is_flag=True, help="The suite's quick episodes and a small budget (a CI-sized run).")
@click.option("--seed", type=int, default=0, show_default=True, help="Seed of the directions and seed draws.")
@click.option("--method", default="ars", show_default=True, metavar="ars|cmaes",
              help="ars: augmented random search V2-t; cmaes: CMA-ES (the cma library), lambda = 2 x --directions, "
                   "initial step size --noise.")
@click.option("--action", default="tau", show_default=True, metavar="tau|actuators",
              help="What the policy commands: normalised tau, or a 6-DOF tier's actuators (rpm, fins).")
@click.option("--scheduler", default=None, metavar="ADDRESS",
              help="Run the training rollouts on an existing Dask scheduler, tcp://host:port (probed first); "
                   "the workers must read the suite file. The numbers are those of a local training.")
@click.option("--quiet", is_flag=True, help="No progress line, no compile notice or bar.")
def train(suite_name: str, tier: str | None, tasks: tuple[str, ...], out: str, iterations: int | None,
          directions: int, top: int, step_size: float, noise: float, seeds_per_iteration: int, eval_every: int,
          substeps: int, duration: float | None, quick: bool, seed: int, method: str, action: str,
          scheduler: str | None, quiet: bool) -> None:
    """Train a policy for a suite's tier by augmented random search or CMA-ES (no deep-learning stack); Ctrl-C or
    SIGTERM keeps every completed iteration, run again to resume.

    The environments' compiled step is compiled (or loaded) before the first episode, with the
    "compiling kernels (first run only, about N s)" notice and a progress bar on a first run.
    """
    from ..benchmark.suite import SuiteError
    from ..gym.train import TrainConfig
    from ..gym.train import train as _train

    cfg = TrainConfig(suite=suite_name, tier=tier, tasks=tuple(tasks),
                      iterations=iterations if iterations is not None else (QUICK_ITERATIONS if quick else ITERATIONS),
                      directions=directions, top=top, step_size=step_size, noise=noise,
                      seeds_per_iteration=seeds_per_iteration, eval_every=eval_every, substeps=substeps,
                      duration=duration, quick=quick, seed=seed, method=method, action=action)

    stopped = None

    def progress(row: dict) -> None:
        if stopped is not None and stopped():  # a signal whose KeyboardInterrupt was lost: stop here
            raise KeyboardInterrupt
        if not quiet:
            val = row["validation_return"]
            click.echo(f"iteration {row['iteration']}/{cfg.iterations}: training return {row['train_return']:.6g}"
                       + (f", held-out return {val:.6g}" if val != "" else "") + f" ({row['env_steps']} env steps)",
                       err=True)

    try:
        cfg.check()
    except ValueError as exc:  # the field named as its option
        field, _, rest = str(exc).partition(":")
        raise BadInput(f"--{field.replace('_', '-')}:{rest}") from None
    client = None
    if scheduler:
        from ..batch.scheduler import SchedulerError, connect_scheduler

        try:
            client = connect_scheduler(scheduler)
        except SchedulerError as exc:
            raise BadInput(str(exc)) from None
    with stop_once() as stopped:
        try:
            res = _train(cfg, out, progress=progress, client=client, compile_bar=not quiet,
                         notify=(lambda text: None) if quiet else None)
        except (SuiteError, ValueError) as exc:
            raise BadInput(one_line(exc)) from None
        except KeyboardInterrupt:
            click.echo(f"auvtrack: interrupted; {out} holds every completed iteration (policy.npz, checkpoint.npz); "
                       "the same command resumes", err=True)
            raise click.exceptions.Exit(EXIT_INTERRUPTED) from None
        finally:
            if client is not None:
                client.close()
    first, last = res.curve[0]["validation_return"], res.curve[-1]["validation_return"]
    click.echo(f"iterations: {len(res.curve) - 1}; episodes: {res.episodes}; env steps: {res.env_steps}; "
               f"wall {res.wall_s:.1f} s")
    click.echo(f"held-out return: initial policy {first:.6g}, trained policy {last:.6g}")
    for k, p in res.outputs.items():
        click.echo(f"{k}: {p}")
