"""``auvtrack scenarios list | copy``: the scenarios shipped with the package, usable from any folder."""
from __future__ import annotations

import click

from .common import EXIT_CODES_HELP, BadInput, cli, one_line


@cli.group()
def scenarios() -> None:
    """List the packaged scenarios, or copy one to a file to edit.

    A packaged scenario runs by its name from any folder (auvtrack run lawnmower). A name is
    letters, digits, _ and - only; anything with a '/' or a '.' (paper.toml, ./paper) is a file
    path.
    """


@scenarios.command("list")
def list_() -> None:
    """Print each packaged scenario's name and description."""
    from ..scenario.catalog import available_scenarios, scenario_summary

    names = available_scenarios()
    width = max((len(n) for n in names), default=0)
    for name in names:
        click.echo(f"{name:<{width}}  {scenario_summary(name)}".rstrip())


@scenarios.command(epilog=EXIT_CODES_HELP)
@click.argument("name")
@click.argument("dest", required=False)
@click.option("--force", is_flag=True, help="Overwrite DEST if it is an existing file.")
def copy(name: str, dest: str | None, force: bool) -> None:
    """Copy packaged scenario NAME to DEST (a file, or a folder to put NAME.toml in; default ./NAME.toml).

    The copy is byte for byte, comments included; an existing file is kept unless --force.
    """
    from ..scenario import ScenarioError
    from ..scenario.catalog import copy_scenario

    try:
        target = copy_scenario(name, dest, overwrite=force)
    except ScenarioError as exc:
        raise BadInput(one_line(exc)) from None
    click.echo(f"written: {target}")
