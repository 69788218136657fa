"""``auvtrack bench | warmup``: speed of the compiled loop, and compiling the kernels up front."""
from __future__ import annotations

import json
import math
import re
from pathlib import Path

import click

from .common import MAX_REPEAT, BadInput, cli, one_line


def _option_given(name: str) -> bool:
    """True when the user gave option ``name`` (not its default)."""
    ctx = click.get_current_context()
    return ctx.get_parameter_source(name) not in (None, click.core.ParameterSource.DEFAULT)


def _check_controllers(controllers: tuple[str, ...], plant: str) -> None:
    """Each ``--controller`` is a built-in kind that runs on ``plant``, or ``plugin:FILE.py``."""
    from ..control import BUILTIN_NAMES
    from ..simulation.compiling import builtin_controllers

    runs_here = builtin_controllers(plant)
    for kind in controllers:
        if kind.startswith("plugin:"):
            continue
        if kind not in BUILTIN_NAMES:
            raise BadInput(f"--controller: unknown controller {kind!r} (allowed: {', '.join(BUILTIN_NAMES)}, "
                           "or plugin:FILE.py)")
        if kind not in runs_here:
            raise BadInput(f"--controller: {kind} does not run on --plant {plant} (controllers that do: "
                           f"{', '.join(runs_here)})")


def _scenario_reason(exc: Exception) -> str:
    """A scenario error without its source and override hint: what the option's value breaks."""
    text = one_line(exc)
    text = re.sub(r"^(?:<dict>|[^:]*\.toml): ", "", text)
    text = re.sub(r" \(raise it deliberately[^)]*\)", "", text)  # bench has no --set
    return re.sub(r" \(set by override '[^']*'\)", "", text)


def _check_duration(duration: float, plant: str) -> None:
    """``--duration`` is a finite time the bench's scenarios on ``plant`` accept (time grid, run plan)."""
    from ..perf.bench import PLANT_BENCH, _prepared

    if not (math.isfinite(duration) and duration > 0):
        raise BadInput(f"--duration: must be a finite number > 0 s (got {duration:g})")
    for source, extra in PLANT_BENCH[plant]:
        try:
            _prepared("ftsmc", duration, source, extra)  # any controller: the grid and the plan are the scenario's
        except ValueError as exc:
            raise BadInput(f"--duration: a {duration:g} s run is refused: {_scenario_reason(exc)}") from None


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
@click.option("--gym", "gym", is_flag=True,
              help="Gymnasium vector environment: env steps/s at N = 1, 64, 1024 and the ratio to the batch runner "
                   "(auvtrack.perf.gym_bench).")
def bench(controllers: tuple[str, ...], repeat: int, duration: float, run_all: bool, bench_out: str | None,
          plant: str = "5dof", gym: bool = False) -> None:
    """Time the compiled closed loop: µs per RK4 step, one JSON line per controller (every built-in by default).

    --all runs the full suite (batch runs/s, Dask sweep throughput) and writes results.json and
    results.md to --out (default: a new user folder; the working tree is left unchanged).
    """
    if not 1 <= repeat <= MAX_REPEAT:
        raise BadInput(f"--repeat: must be in [1, {MAX_REPEAT}] (a median needs at least one timing) (got {repeat})")
    if gym:
        unused = [option for option, param in (("--controller", "controllers"), ("--duration", "duration"),
                                               ("--plant", "plant"), ("--all", "run_all"), ("--out", "bench_out"))
                  if _option_given(param)]
        if unused:
            raise BadInput(f"{', '.join(unused)}: not used by --gym (it times its own cell; --repeat applies)")
        from ..perf.gym_bench import bench_gym

        click.echo(json.dumps(bench_gym(repeat=repeat)))
        return
    if run_all:
        unused = [option for option, param in (("--controller", "controllers"), ("--duration", "duration"),
                                               ("--plant", "plant")) if _option_given(param)]
        if unused:
            raise BadInput(f"{', '.join(unused)}: not used by --all (it runs its own fixed suite)")
    else:
        if bench_out is not None:
            raise BadInput("--out: only --all writes results (without it, bench prints JSON lines)")
        _check_controllers(controllers, plant)
        _check_duration(duration, plant)

    if run_all:
        from ..perf.bench import bench_all

        doc = bench_all(repeat=repeat, out=Path(bench_out) if bench_out else None, progress=True)
        folder = doc.pop("out")
        click.echo(json.dumps(doc, indent=2))
        click.echo(f"written: {folder / 'results.json'}, {folder / 'results.md'}")
        return
    from ..perf.bench import bench_plant, bench_singles
    from ..simulation.compiling import builtin_controllers

    if plant != "5dof":  # the 6-DOF truths, one line per (controller, preset)
        for row in bench_plant(controllers or ("ftsmc", "fxtntsmc"), plant, repeat=repeat, duration=duration,
                               progress=True):
            click.echo(json.dumps(row))
        return
    for row in bench_singles(controllers or builtin_controllers(), repeat=repeat, duration=duration,
                             progress=True):
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
    from ..control import BUILTIN_NAMES
    from ..plant import BUILTIN_NAMES as PLANT_NAMES
    from ..simulation.compiling import builtin_pairs, warmup as _warmup

    for option, given, allowed in (("--controller", controllers, BUILTIN_NAMES), ("--plant", plants, PLANT_NAMES)):
        for name in given:
            if name not in allowed:
                raise BadInput(f"{option}: unknown {option[2:]} {name!r} (allowed: {', '.join(allowed)})")
    if not builtin_pairs(controllers, plants):
        raise BadInput(f"--controller, --plant: nothing to compile: no controller given runs on a plant given "
                       f"({', '.join(controllers)} on {', '.join(plants)})")
    click.echo(json.dumps(_warmup(controllers, plants, progress=True, simd=simd)))
