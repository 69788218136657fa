"""``auvtrack reproduce | study``: the paper's Section 4 and the registered studies."""
from __future__ import annotations

import json
from pathlib import Path

import click

from .common import BadInput, cli
from .digest import reproduce_lines


@cli.command()
@click.option("--out", type=click.Path(file_okay=False), default="reproduce", show_default=True,
              help="Output folder (overwritten).")
@click.option("--quick", is_flag=True, help="Short horizon (smoke test).")
def reproduce(out: str, quick: bool) -> None:
    """Reproduce the paper's Section 4: both controllers, Figures 3-8, metrics and a verdict on each claim.

    Writes the run folders, figures/, metrics.json, summary.md and report.html (one
    self-contained page with every figure) to --out.
    """
    from ..report import quick_outputs
    from ..studies.reproduce import reproduce as _reproduce

    with quick_outputs(quick):
        _reproduce(Path(out), quick=quick, progress=True)
    metrics = json.loads((Path(out) / "metrics.json").read_text(encoding="utf-8"))
    click.echo("\n".join(reproduce_lines(metrics)))
    click.echo(f"written: {Path(out) / 'summary.md'}, {Path(out) / 'report.html'}")


class _StudyCommand(click.Command):
    """``auvtrack study``: its ``--help`` lists the registered studies with their summaries."""

    def format_epilog(self, ctx: click.Context, formatter: click.HelpFormatter) -> None:
        from ..studies.registry import all_studies

        with formatter.section("Studies"):
            formatter.write_dl([(n, s.summary) for n, s in sorted(all_studies().items())])
        super().format_epilog(ctx, formatter)


@cli.command(cls=_StudyCommand)
@click.argument("name")
@click.option("--out", type=click.Path(file_okay=False), default=None, help="Output folder (default studies/<NAME>).")
@click.option("--quick", is_flag=True, help="CI-sized run (seconds instead of minutes).")
@click.option("--pulse", default=None, metavar="F1,F2,F3,F4,F5",
              help="ablation: one pulse direction (N, N, N, N m, N m per unit amplitude) instead of the defaults.")
@click.option("--pulse-start", "pulse_start", type=float, default=None, metavar="T",
              help="ablation: pulse onset in s (default 20; the run lasts until T + 20 s).")
@click.option("--controllers", default=None, metavar="KIND,KIND",
              help="model-gap: the controllers to fly (default every built-in tracking controller; e.g. policy,pid).")
def study(name: str, out: str | None, quick: bool, pulse: str | None, pulse_start: float | None,
          controllers: str | None) -> None:
    """Run study NAME and write report.md, report.html, results.json and figures/ (NAME 'list': list them)."""
    from ..studies.registry import all_studies, get_study, run_study

    if name == "list":
        for n, spec in sorted(all_studies().items()):
            click.echo(f"{n}: {spec.summary}")
        return
    try:
        spec = get_study(name)
    except KeyError as e:
        raise BadInput(str(e.args[0])) from None
    kinds = None if controllers is None else controllers.split(",")
    options = {k: v for k, v in (("pulse", pulse), ("pulse_start", pulse_start), ("controllers", kinds)) if v is not None}
    for k in options:
        if k not in spec.options:
            raise BadInput(f"--{k.replace('_', '-')}: not an option of study {name!r}")
    if kinds is not None:
        from ..studies.model_gap import check_kinds

        try:
            options["controllers"] = check_kinds(kinds)
        except ValueError as exc:
            raise BadInput(str(exc)) from None
    report = run_study(spec, Path(out) if out else Path("studies") / name, quick=quick, progress=True, **options)
    html = report.with_suffix(".html")
    click.echo(f"report: {report}" + (f", {html}" if html.exists() else ""))
