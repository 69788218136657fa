"""Command line: ``auvtrack reproduce | run | check | bounds | scenarios | study | sweep | compare | bench | warmup``.

Bad input (a scenario error, a missing file, an invalid gain, a run over the plan's limits, an
output folder that cannot be written) prints ONE line to stderr and exits with status 2, never a
traceback, and before anything runs.  ``check`` runs exactly the validation of ``run`` (load,
plan, controller set-up), so it refuses the same scenarios with the same message.  A simulation
that fails (divergence, pitch limit, envelope violation) keeps and saves its partial result,
prints the diagnostic and exits 3.  Ctrl-C or SIGTERM stops a run within about a second, saves
what was computed with status ``interrupted`` and exits 130; a sweep closes its cluster, keeps
its completed chunks for ``--resume`` and exits 130 (so does ``compare``; ``tune`` keeps its
study, ``train`` its checkpoint).  Every command runs inside one handler of both signals
(:func:`auvtrack.cli.signals.stop_once`): the first stops the command with one line and exit
130, later ones are ignored while it cleans up.  ``auvtrack --help`` lists every command and
these exit codes.
"""
from __future__ import annotations

import traceback
import warnings

import click

from . import compare, perf, run, scenarios, studies, sweep, train, tune  # noqa: F401  (each registers its commands on the group)
from .common import EXIT_BAD_INPUT, EXIT_CODES, EXIT_INTERRUPTED, EXIT_SIM_FAILED, VERBOSE, cli, one_line
from .signals import stop_once

__all__ = ["cli", "main", "EXIT_BAD_INPUT", "EXIT_SIM_FAILED", "EXIT_INTERRUPTED", "EXIT_CODES"]


def _details(text: str) -> None:
    """With ``--verbose``, the full report of an error after its one line."""
    if VERBOSE["on"] and text:
        click.echo(text.rstrip(), err=True)


def main(argv: list[str] | None = None) -> int:
    """Entry point of the ``auvtrack`` console script; returns the exit status.

    When user code (a plug-in's law or plant) was still running when Ctrl-C came and had to be
    abandoned, the process ends here with ``os._exit`` once everything is written: an interpreter
    shutting down under running compiled code could crash instead of exiting with 130.
    """
    code = _main(argv)
    from ..interrupt import abandoned

    if abandoned():
        import os
        import sys

        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(code)
    return code


def _main(argv: list[str] | None) -> int:
    """Run one command inside the signal handling every command shares (:func:`~auvtrack.cli.signals.stop_once`)."""
    with stop_once():  # SIGINT and SIGTERM alike: the first stops the command, later ones wait for its clean-up
        try:
            return _dispatch(argv)
        except KeyboardInterrupt:  # a signal while an error message was printed
            click.echo("auvtrack: interrupted", err=True)
            return EXIT_INTERRUPTED


def _dispatch(argv: list[str] | None) -> int:
    from ..scenario import ScenarioError

    warnings.simplefilter("default")
    VERBOSE["on"] = False
    try:
        rv = cli.main(args=argv, prog_name="auvtrack", standalone_mode=False)
    except click.exceptions.Exit as e:
        return e.exit_code
    except click.UsageError as e:  # one line too, with where to look
        where = f" (see '{e.ctx.command_path} --help')" if e.ctx is not None else ""
        click.echo(f"auvtrack: error: {one_line(e.format_message())}{where}", err=True)
        return EXIT_BAD_INPUT
    except click.ClickException as e:
        e.show()
        _details(getattr(e, "details", ""))
        return e.exit_code
    except click.exceptions.Abort:  # Ctrl-C outside a simulation (loading, compiling, saving)
        click.echo("auvtrack: interrupted", err=True)
        return EXIT_INTERRUPTED
    except (ScenarioError, ValueError, KeyError, OSError) as e:
        click.echo(f"auvtrack: error: {one_line(e)}", err=True)
        _details(getattr(e, "details", "") or "".join(traceback.format_exception(e)))
        return EXIT_BAD_INPUT
    # without standalone mode, click returns the code of a raised ``Exit`` instead of exiting
    return rv if isinstance(rv, int) else 0
