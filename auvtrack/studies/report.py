"""Small shared helpers for study reports: Markdown with tables and figures, and JSON output.

A study builds a :class:`Report`, adds headings, paragraphs, tables and figures, then calls
:meth:`Report.write`.  Figures are saved as PNG under ``<out>/figures`` and linked relatively,
so the report folder can be moved as a whole.  Numbers are formatted by :func:`fmt`, metric
tables by :func:`metrics_table`, and data files are written by :func:`write_json`, which turns
every non-finite float (a settling time that never settled, a failed run's metric) into
``null`` so that the file is strict JSON.

Examples
--------
>>> from pathlib import Path
>>> rep = Report(Path("studies/demo"), "Demo")              # doctest: +SKIP
>>> rep.table(["config", "value"], [["a", 1.23456], ["b", float("inf")]])  # doctest: +SKIP
>>> rep.write()                                             # doctest: +SKIP
PosixPath('studies/demo/report.md')
"""
from __future__ import annotations

import json
import math
import sys
from pathlib import Path
from typing import Any, Iterable, Mapping, Sequence

from ..simulation.result import to_jsonable

__all__ = ["Report", "failure_cause", "fmt", "metrics_table", "markdown_table", "write_json"]

CAUSES = ("envelope_violation", "pitch_limit", "nonfinite", "state_limit", "nonfinite_input",
          "start_refused", "controller")
"""Failure causes reported by :func:`failure_cause`."""


def failure_cause(result: Any) -> str | None:
    """Short failure cause of a :class:`~auvtrack.simulation.result.Result`, ``None`` if it is ok.

    The engine's causes (``pitch_limit``, ``nonfinite``, ``state_limit``) are kept; a
    controller failure is split by its detail into ``envelope_violation``,
    ``nonfinite_input`` and ``start_refused`` (anything else stays ``controller``).
    """
    f = getattr(result, "failure", None)
    if not f:
        return None
    cause, detail = f.get("cause", "controller"), str(f.get("detail", ""))
    if cause != "controller":
        return cause
    if detail.startswith("envelope violated"):
        return "envelope_violation"
    if "non-finite input" in detail:
        return "nonfinite_input"
    if "widen_start is off" in detail:
        return "start_refused"
    return "controller"


def fmt(x: Any, digits: int = 4) -> str:
    """Format one table cell: floats to ``digits`` significant digits, non-finite as text.

    Parameters
    ----------
    x : object
        Value; ``None`` and NaN print as ``–``, infinities as ``inf`` / ``-inf``.
    digits : int, optional
        Significant digits for floats.

    Returns
    -------
    str
    """
    if x is None:
        return "–"
    if isinstance(x, bool):
        return "yes" if x else "no"
    if isinstance(x, int):
        return str(x)
    if isinstance(x, float):
        if math.isnan(x):
            return "–"
        if math.isinf(x):
            return "inf" if x > 0 else "-inf"
        return f"{x:.{digits}g}"
    return str(x).replace("|", "\\|").replace("\n", " ")


def markdown_table(headers: Sequence[str], rows: Iterable[Sequence[Any]], digits: int = 4) -> str:
    """Return a Markdown table; every cell goes through :func:`fmt`."""
    lines = ["| " + " | ".join(str(h) for h in headers) + " |", "|" + "---|" * len(headers)]
    for row in rows:
        cells = [fmt(c, digits) for c in row]
        if len(cells) != len(headers):
            raise ValueError(f"table row has {len(cells)} cells, expected {len(headers)}")
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


def metrics_table(metrics: Mapping[str, Mapping[str, Any]], keys: Sequence[str], *,
                  label: str = "configuration", digits: int = 4) -> str:
    """Markdown table with one row per configuration and one column per metric.

    Parameters
    ----------
    metrics : mapping of str to mapping
        ``{row label: {metric name: value}}``; missing metrics print as ``–``.
    keys : sequence of str
        Metric names, in column order.
    label : str, optional
        Header of the first column.
    digits : int, optional
        Significant digits.

    Returns
    -------
    str
    """
    rows = [[name, *[vals.get(k) for k in keys]] for name, vals in metrics.items()]
    return markdown_table([label, *keys], rows, digits)


def write_json(path: str | Path, obj: Any) -> Path:
    """Write ``obj`` as strict JSON (non-finite floats become ``null``); return the path.

    NumPy arrays and scalars, tuples and paths are converted as well
    (:func:`auvtrack.simulation.result.to_jsonable`).
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(to_jsonable(obj), indent=2, allow_nan=False) + "\n", encoding="utf-8")
    return path


class Report:
    """A Markdown report under construction, written to ``<out>/report.md``.

    Parameters
    ----------
    out : pathlib.Path
        Report folder (created on :meth:`write` or :meth:`figure`).
    title : str
        Level-1 heading.
    """

    def __init__(self, out: str | Path, title: str) -> None:
        self.out = Path(out)
        self.parts: list[str] = [f"# {title}", ""]
        self.figures: list[Path] = []

    def heading(self, text: str, level: int = 2) -> None:
        """Add a heading of ``level`` (2 = section)."""
        self.parts += ["#" * level + " " + text, ""]

    def paragraph(self, text: str) -> None:
        """Add a paragraph (Markdown allowed)."""
        self.parts += [text.strip(), ""]

    def bullets(self, items: Iterable[str]) -> None:
        """Add a bullet list."""
        self.parts += [f"- {it}" for it in items] + [""]

    def table(self, headers: Sequence[str], rows: Iterable[Sequence[Any]], digits: int = 4) -> None:
        """Add a table (see :func:`markdown_table`)."""
        self.parts += [markdown_table(headers, rows, digits), ""]

    def markdown(self, text: str) -> None:
        """Add pre-formatted Markdown (e.g. :func:`metrics_table`) verbatim."""
        self.parts += [text, ""]

    def figure(self, fig: Any, name: str, caption: str = "", dpi: int = 120) -> Path:
        """Save a Matplotlib figure as ``figures/<name>.png`` and link it.

        Build figures with :class:`matplotlib.figure.Figure` (no pyplot, no GUI backend); a
        pyplot figure is closed after saving.

        Returns
        -------
        pathlib.Path
            The PNG path.
        """
        path = self.out / "figures" / f"{name}.png"
        path.parent.mkdir(parents=True, exist_ok=True)
        fig.savefig(path, dpi=dpi, bbox_inches="tight")
        if "matplotlib.pyplot" in sys.modules:  # a pyplot-managed figure: release it
            sys.modules["matplotlib.pyplot"].close(fig)
        self.figures.append(path)
        self.parts += [f"![{caption or name}](figures/{name}.png)", ""]
        if caption:
            self.parts += [f"*{caption}*", ""]
        return path

    def text(self) -> str:
        """The Markdown written so far."""
        return "\n".join(self.parts).rstrip() + "\n"

    def write(self, name: str = "report.md") -> Path:
        """Write the report to ``<out>/<name>`` and return its path."""
        self.out.mkdir(parents=True, exist_ok=True)
        path = self.out / name
        path.write_text(self.text(), encoding="utf-8")
        return path
