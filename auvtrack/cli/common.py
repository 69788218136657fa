"""Shared pieces of the command line: the ``auvtrack`` group, one-line errors, exit codes, options."""
from __future__ import annotations

import inspect

import click

EXIT_BAD_INPUT = 2
EXIT_SIM_FAILED = 3
EXIT_INTERRUPTED = 130
MAX_REPEAT = 1000
LONG_RUN_STEPS = 1_000_000  # runs this long announce themselves (and that Ctrl-C keeps their result)


VERBOSE = {"on": False}
"""Set by ``auvtrack --verbose``: an error also prints its full report."""


class BadInput(click.ClickException):
    """Any user error: shown as one line, exit status 2 (``details``: the full report for ``--verbose``)."""

    exit_code = EXIT_BAD_INPUT

    def __init__(self, message: str, details: str = ""):
        super().__init__(message)
        self.details = details

    def show(self, file=None) -> None:  # noqa: D102 - one line, no "Error:" banner
        click.echo(f"auvtrack: error: {self.format_message()}", err=True)


def load_arg(scenario: str, overrides: tuple[str, ...]):
    """The validated scenario of a command's SCENARIO argument (a file or a packaged name) and its --set.

    A sweep's study file or a benchmark suite given instead is named as such, with the command that runs it.
    """
    from ..scenario import ScenarioError, load_scenario

    try:
        return load_scenario(scenario, list(overrides))
    except ScenarioError:
        other = _other_file_kind(scenario)
        if other:
            raise ScenarioError(f"{scenario}: {other}") from None
        raise


def _other_file_kind(path: str) -> str:
    """What to say about a TOML file that is a sweep's study file or a benchmark suite, not a scenario ("" otherwise).

    A file is taken for one when it has keys a scenario does not and every one of its keys is a
    key of that file kind (:class:`auvtrack.batch.sweep_spec.StudyFile`,
    :class:`auvtrack.benchmark.suite.SuiteFile`).
    """
    from ..batch.sweep_spec import StudyFile
    from ..benchmark.suite import SuiteFile
    from ..scenario import Scenario, ScenarioError, read_toml

    try:
        keys = set(read_toml(path)) if path.endswith(".toml") else set()
    except ScenarioError:
        return ""
    if not keys - set(Scenario.model_fields):
        return ""
    if keys <= set(StudyFile.model_fields):
        return ("a sweep's study file (keys scenario, grid, random, ...), not a scenario: run it with "
                f"`auvtrack sweep {path}` (docs/sweeps.md)")
    if keys <= set(SuiteFile.model_fields):
        return ("a benchmark suite (keys tasks, tiers, seeds, ...), not a scenario: run it with "
                f"`auvtrack compare --suite {path}` (docs/benchmark.md)")
    return ""


def prepare_arg(scenario: str, sc):
    """The run's validation after loading: plan, set-up, a plug-in law's probe (``check`` = ``run`` minus the run)."""
    from ..simulation.pipeline import prepare
    from ..simulation.probe import probe

    try:
        prep = prepare(sc)
        probe(prep)
        return prep
    except ValueError as exc:  # ScenarioError of the plan, or a controller refusing its set-up
        import traceback

        raise BadInput(f"{scenario}: {one_line(exc)}",
                       getattr(exc, "details", "") or "".join(traceback.format_exception(exc))) from None


def mib(n: int) -> str:
    """``n`` bytes in MiB, three significant digits."""
    return f"{n / 2 ** 20:.3g} MiB"


def one_line(exc: BaseException) -> str:
    """The message of ``exc`` on one line (its type name when it has none)."""
    return " ".join(str(exc).split()) or type(exc).__name__


EXIT_CODES = (("0", "success"),
              ("2", "bad input: one line naming the field and the allowed range, no traceback, nothing run"),
              ("3", "a simulation failed (diverged, pitch limit, envelope violated): the diagnostic is printed "
                    "and the partial result kept"),
              ("130", "interrupted (Ctrl-C or SIGTERM, any command): a run keeps its partial "
                      "result, a sweep or a comparison its completed chunks, a tuning its study, a training its "
                      "completed iterations"))
EXIT_CODES_HELP = "Exit status: " + "; ".join(f"{code} {text}" for code, text in EXIT_CODES) + "."
COMMAND_ORDER = ("reproduce", "run", "check", "bounds", "scenarios", "study", "sweep", "compare", "bench", "warmup")


def _first_paragraph(text: str | None) -> str:
    return " ".join(inspect.cleandoc(text or "").split("\n\n")[0].split())


class _Group(click.Group):
    """Top-level group: every command with its whole first help paragraph, then the exit codes."""

    def list_commands(self, ctx: click.Context) -> list[str]:
        names = super().list_commands(ctx)
        return [n for n in COMMAND_ORDER if n in names] + [n for n in names if n not in COMMAND_ORDER]

    def format_commands(self, ctx: click.Context, formatter: click.HelpFormatter) -> None:
        rows = [(n, _first_paragraph(c.help)) for n in self.list_commands(ctx)
                if (c := self.get_command(ctx, n)) is not None and not c.hidden]
        with formatter.section("Commands"):
            formatter.write_dl(rows)

    def invoke(self, ctx: click.Context):  # noqa: D102 - Ctrl-C or SIGTERM: one line (click prints an empty one first)
        try:
            return super().invoke(ctx)
        except KeyboardInterrupt:
            raise click.exceptions.Abort() from None

    def format_epilog(self, ctx: click.Context, formatter: click.HelpFormatter) -> None:
        with formatter.section("Exit status"):
            formatter.write_dl(list(EXIT_CODES))
        super().format_epilog(ctx, formatter)


@click.group(cls=_Group, context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(package_name="auvtrack")
@click.option("--verbose", is_flag=True, help="On an error, also print its full report (traceback, compiler report).")
def cli(verbose: bool) -> None:
    """auvtrack: trajectory-tracking control of underactuated AUVs.

    Scenarios are TOML files in which every key has a default; an empty file is the paper's
    Section 4.  The packaged ones run by name from any folder (`auvtrack run paper`), and
    `auvtrack scenarios copy paper` writes the commented Section 4 file to edit.  Start with
    `auvtrack reproduce`.  The first command after
    installing or editing the package compiles the Numba kernels (about a minute, more on a
    loaded machine; cached on disk afterwards); `auvtrack warmup` does that up front.
    """
    VERBOSE["on"] = verbose


set_option = click.option("--set", "overrides", multiple=True, metavar="KEY=VALUE",
                          help="Override a scenario key, e.g. --set sim.dt=0.002 (repeatable).")
