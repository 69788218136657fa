"""``auvtrack run | check | bounds``: one scenario, simulated, validated, or its Theorem 1 bounds."""
from __future__ import annotations

import json
from pathlib import Path

import click

from ..simulation.manoeuvre import manoeuvre_line
from .common import (EXIT_CODES_HELP, EXIT_INTERRUPTED, EXIT_SIM_FAILED, LONG_RUN_STEPS, BadInput, cli, load_arg, mib,
                     one_line, prepare_arg, set_option)
from .digest import saturation_warning
from .signals import stop_requests


def _note_kind(note: str) -> str:
    """``warning`` for a start off the reference (a run may fail on it), ``note`` for other set-up notes."""
    from ..reference.start import NOTE_PREFIX

    return "warning" if note.startswith(NOTE_PREFIX) else "note"


@cli.command(epilog=EXIT_CODES_HELP)
@click.argument("scenario")
@click.option("--out", default=None, metavar="FOLDER",
              help="Run folder, replaced as a whole if it exists and holds only a run (default: a new "
                   "runs/<name>-<controller>, numbered -2, -3, ... when taken).")
@set_option
@click.option("--mat", is_flag=True, help="Also write trajectory.mat (MATLAB).")
def run(scenario: str, out: str | None, overrides: tuple[str, ...], mat: bool) -> None:
    """Simulate SCENARIO (a TOML file or a packaged name): trajectory.csv, run.json, scenario.toml in a run folder.

    Without --out every run gets a new folder runs/<name>-<controller> (then -2, -3, ...), so a
    second run never overwrites the first; the folder is printed.  The folder is checked before
    the simulation starts, and scenario.toml reproduces the run (auvtrack run <folder>/scenario.toml).
    A name (auvtrack scenarios list) has no '/' and no '.'; paper.toml or ./paper is a file.
    """
    from ..control import spec_for
    from ..simulation.compiling import ensure_compiled
    from ..simulation.pipeline import SimulationInterrupted, run_prepared
    from ..simulation.result import FolderError, prepare_run_folder
    from ..simulation.run_folder import default_run_folder

    sc = load_arg(scenario, overrides)
    prep = prepare_arg(scenario, sc)
    target = Path(out) if out is not None else default_run_folder(sc.name, sc.controller.kind)
    try:  # before the run: an unwritable folder must not cost the simulation
        prepare_run_folder(target)
    except FolderError as exc:
        raise BadInput(f"{'--out' if out is not None else 'run folder'}: {one_line(exc)}") from None
    for note in prep.notes:
        click.echo(f"{_note_kind(note)}: {note}", err=True)
    if spec_for(sc.controller).tracks:  # a reference the plant cannot fly: say so, fly anyway
        from ..feasibility import assess

        if (line := assess(sc).warning()) is not None:
            click.echo(f"warning: {line}", err=True)
    ensure_compiled([prep])  # compile or load the kernel first: Ctrl-C from here on stops the simulation
    if prep.n_steps >= LONG_RUN_STEPS:
        click.echo(f"running {prep.n_steps} RK4 steps (Ctrl-C stops the run and keeps its partial result)", err=True)
    try:
        res = run_prepared(prep)
    except SimulationInterrupted as exc:  # stopped within about a second; write what was computed
        res = exc.result
    tracks = spec_for(sc.controller).tracks
    manoeuvre = res.meta.get("manoeuvre")  # an open-loop run: its manoeuvre, not a tracking error, is the result
    try:  # Ctrl-C while the folder is written: keep the rows written so far, publish, exit 130
        with stop_requests() as requested:
            folder = res.save(target, mat=mat or sc.output.mat, overwrite=out is not None, stop=requested)
    except OSError as exc:  # FolderError (the folder changed since the check), a full disk...
        click.echo(f"auvtrack: error: the run folder {target} could not be written: {one_line(exc)}", err=True)
        raise click.exceptions.Exit(EXIT_SIM_FAILED) from None
    click.echo(f"{res!r}\nwritten: {folder}")
    if manoeuvre is not None:
        click.echo(manoeuvre_line(manoeuvre))
    if res.ok and tracks and (line := saturation_warning(res.metrics, float(res.t[-1]))) is not None:
        click.echo(f"warning: {line}", err=True)
    if requested():
        kept = json.loads((folder / "run.json").read_text(encoding="utf-8"))["files"]["trajectory.csv"]
        rows = kept.get("rows", len(res))
        click.echo(f"auvtrack: interrupted while writing the run folder; trajectory.csv holds {rows} of {len(res)} "
                   f"rows, run.json the whole run's status and metrics: kept in {folder}", err=True)
        raise click.exceptions.Exit(EXIT_INTERRUPTED)
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

    Warns where the controller's own conditions fail (the FXTNTSMC: Theorem 1), and prints whether the
    plant can fly the reference (trim, surge, tightest turn against the limits; docs/vehicles.md#feasibility).
    """
    from ..control import spec_for
    from ..scenario.plan import plan_run

    sc = load_arg(scenario, overrides)
    prep = prepare_arg(scenario, sc)
    for note in prep.notes:
        click.echo(f"{_note_kind(note)}: {note}", err=True)
    spec = spec_for(sc.controller)
    for v in (spec.warnings(sc.controller) if spec.warnings else []):
        click.echo(f"warning: {v}", err=True)
    plan = plan_run(sc, len(prep.channels))
    click.echo(f"ok: {scenario} ({sc.name}: controller {sc.controller.kind}, "
               f"{sc.sim.duration:g} s at dt {sc.sim.dt:g} s: {plan.n_steps} steps, {plan.log_rows} logged rows, "
               f"~{mib(plan.memory_bytes)})")
    from ..feasibility import assess

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
    from ..control import fxtntsmc
    from ..control.fxtntsmc.theory import fixed_time_bounds

    sc = load_arg(scenario, overrides)
    if not isinstance(sc.controller, fxtntsmc.Params):  # Theorem 1 is the FXTNTSMC's
        raise BadInput(f"controller.kind: bounds exist for 'fxtntsmc' only (got {sc.controller.kind!r})")
    b = fixed_time_bounds(sc.controller, gamma1=gamma1, g1=g1, g2=g2, horizon=sc.sim.duration)
    click.echo(json.dumps(b.to_dict(), indent=2) if as_json else b.report())
