"""``auvtrack bench | warmup``: speed of the compiled loop, and compiling the kernels up front."""
from __future__ import annotations

import json
from pathlib import Path

import click

from .common import MAX_REPEAT, BadInput, cli


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
        from ..perf.bench import bench_all

        doc = bench_all(repeat=repeat, out=Path(bench_out) if bench_out else None, progress=True)
        folder = doc.pop("out")
        click.echo(json.dumps(doc, indent=2))
        click.echo(f"written: {folder / 'results.json'}, {folder / 'results.md'}")
        return
    from ..perf.bench import bench_plant, bench_singles
    from ..simulation.compiling import builtin_controllers

    if plant != "5dof":  # the 6-DOF truths, one line per (controller, preset)
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
    from ..simulation.compiling import warmup as _warmup

    click.echo(json.dumps(_warmup(controllers, plants, progress=True, simd=simd)))
