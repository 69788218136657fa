"""Shared report builder of ``reproduce`` and every study: Markdown and a self-contained HTML page.

A study builds a :class:`Report`, adds headings, paragraphs, tables, verdicts and figures, then
calls :meth:`Report.write`, which writes ``report.md`` and, from the same blocks, a
self-contained ``report.html`` (figures embedded as base64 PNG, rendered by the Jinja2 template
``auvtrack/templates/report.html.j2``).  Both end with the scenario the runs start from and the
version of auvtrack that produced them.  Figures are saved as PNG under ``<out>/figures`` and
linked relatively from the Markdown, so the report folder can be moved as a whole.  Numbers are
formatted by :func:`fmt`, metric tables by :func:`metrics_table`, and data files are written by
:func:`write_json`, which turns every non-finite float (a settling time that never settled, a
failed run's metric) into ``null`` so that the file is strict JSON.

Examples
--------
>>> from pathlib import Path
>>> rep = Report(Path("studies/demo"), "Demo")              # doctest: +SKIP
>>> rep.table(["config", "value"], [["a", 1.23456], ["b", float("inf")]])  # doctest: +SKIP
>>> rep.write()                                             # doctest: +SKIP
PosixPath('studies/demo/report.md')                          # and studies/demo/report.html
"""
from __future__ import annotations

import base64
import contextlib
import contextvars
import json
import math
import re
import sys
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Iterable, Mapping, Sequence

from .report_figures import FIGURE_AREA_REM, make_readable
from .simulation.result import to_jsonable

__all__ = ["Report", "Block", "failure_cause", "fmt", "metrics_table", "markdown_table", "write_json",
           "inline_html", "markdown_blocks", "provenance"]

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


_QUICK: contextvars.ContextVar[bool] = contextvars.ContextVar("auvtrack_quick_outputs", default=False)
QUICK_BANNER = ("**Quick run** (`--quick`, CI-sized): short horizons and few cases; the numbers are a smoke test, "
                "not the study's result.")


@contextlib.contextmanager
def quick_outputs(quick: bool = True):
    """Mark what a ``--quick`` run writes inside the block: a banner opening each report, ``"quick": true`` in results.

    Parameters
    ----------
    quick : bool, optional
        Whether the run is a quick one (False: nothing is marked).

    Yields
    ------
    None
    """
    token = _QUICK.set(bool(quick))
    try:
        yield
    finally:
        _QUICK.reset(token)


def metric_unit(name: str) -> str:
    """The unit of metric ``name`` (``rmse_x`` -> ``m``, ``max_abs_tau_q`` -> ``N*m``), from :data:`auvtrack.metrics.METRIC_UNITS`.

    Parameters
    ----------
    name : str
        A metric name (its family, then an axis or input suffix).

    Returns
    -------
    str
        The unit for that axis or input ("" for an unknown family).
    """
    from .metrics import METRIC_UNITS

    suffix = name.rpartition("_")[2]
    family = name if name in METRIC_UNITS else name.rpartition("_")[0]
    while family and family not in METRIC_UNITS:
        family = family.rpartition("_")[0]
    unit = METRIC_UNITS.get(family, "")
    if " (u) or " in unit:  # "N (u) or N*m (q, r)": the input's own
        first, rest = unit.split(" (u) or ", 1)
        unit = first if suffix == "u" else rest.split(" (", 1)[0]
    return unit


def write_json(path: str | Path, obj: Any) -> Path:
    """Write ``obj`` as strict JSON (non-finite floats become ``null``); return the path.

    NumPy arrays and scalars, tuples and paths are converted as well
    (:func:`auvtrack.simulation.result.to_jsonable`).  Inside :func:`quick_outputs` a dict
    document gets ``"quick": true`` first.
    """
    if _QUICK.get() and isinstance(obj, Mapping):
        obj = {"quick": True, **{k: v for k, v in obj.items() if k != "quick"}}
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(to_jsonable(obj), indent=2, allow_nan=False) + "\n", encoding="utf-8")
    return path


@dataclass(frozen=True)
class Block:
    """One element of a report, rendered to Markdown and to HTML from the same data.

    Attributes
    ----------
    kind : str
        ``heading`` (text, level), ``paragraph`` (text), ``bullets`` (items), ``table``
        (headers, rows of formatted cells), ``markdown`` (text, blocks), ``figure`` (path,
        caption, png), ``verdicts`` (rows of claim, verdict, evidence) or ``code`` (label, text).
    data : dict
        The block's content.
    """

    kind: str
    data: dict


def inline_html(text: str) -> str:
    """Markdown inline markup of report text as HTML: code spans, links, bold and italics.

    Only what the reports use is supported (CommonMark-like: ``*`` needs a non-space inside
    and no word character outside, ``_`` is never emphasis, since metric names contain it);
    everything else is escaped.

    Parameters
    ----------
    text : str
        One paragraph, bullet or table cell.

    Returns
    -------
    str
        HTML, safe to embed.
    """
    from markupsafe import escape

    out = []
    for i, part in enumerate(re.split(r"`([^`]*)`", text)):
        if i % 2:
            out.append(f"<code>{escape(part)}</code>")
            continue
        h = str(escape(part.replace("\\|", "|")))
        h = re.sub(r"\[([^\]]+)\]\(([^)\s]+)\)", r'<a href="\2">\1</a>', h)
        h = re.sub(r"\*\*(?=\S)(.+?)(?<=\S)\*\*", r"<strong>\1</strong>", h)
        h = re.sub(r"(?<![\w*])\*(?=[^\s*])(.+?)(?<=[^\s*])\*(?![\w*])", r"<em>\1</em>", h)
        out.append(h)
    return "".join(out)


def _table_cells(line: str) -> list[str]:
    cells = re.split(r"(?<!\\)\|", line.strip().strip("|"))
    return [c.strip() for c in cells]


def markdown_blocks(text: str) -> list[Block]:
    """Split pre-formatted Markdown into blocks for the HTML page.

    Understands what the reports write: ``#`` headings, ``|`` tables (header, separator, rows),
    ``-`` / ``*`` bullet lists, fenced code and paragraphs separated by blank lines.

    Parameters
    ----------
    text : str
        Markdown.

    Returns
    -------
    list of Block
        ``heading``, ``table``, ``bullets``, ``code`` and ``paragraph`` blocks, in order.
    """
    blocks: list[Block] = []
    lines = text.splitlines()
    i = 0
    while i < len(lines):
        line = lines[i]
        if not line.strip():
            i += 1
        elif line.startswith("```"):
            j = i + 1
            while j < len(lines) and not lines[j].startswith("```"):
                j += 1
            blocks.append(Block("code", {"label": "", "text": "\n".join(lines[i + 1:j])}))
            i = j + 1
        elif re.match(r"#{1,6} ", line):
            hashes, _, rest = line.partition(" ")
            blocks.append(Block("heading", {"text": rest.strip(), "level": len(hashes)}))
            i += 1
        elif line.lstrip().startswith("|"):
            j = i
            while j < len(lines) and lines[j].lstrip().startswith("|"):
                j += 1
            rows = [_table_cells(x) for x in lines[i:j] if not re.fullmatch(r"[\s|:\-]+", x)]
            blocks.append(Block("table", {"headers": rows[0] if rows else [], "rows": rows[1:]}))
            i = j
        elif re.match(r"\s*[-*] ", line):
            items = []
            while i < len(lines) and lines[i].strip():
                if re.match(r"\s*[-*] ", lines[i]):
                    items.append(lines[i].strip()[2:].strip())
                elif items:  # a continuation line
                    items[-1] += " " + lines[i].strip()
                i += 1
            blocks.append(Block("bullets", {"items": items}))
        else:
            j = i
            while j < len(lines) and lines[j].strip() and not lines[j].lstrip().startswith(("|", "#", "```")):
                j += 1
            blocks.append(Block("paragraph", {"text": " ".join(x.strip() for x in lines[i:max(j, i + 1)])}))
            i = max(j, i + 1)
    return blocks


def provenance() -> str:
    """One line naming the software that produced a report (auvtrack version and sources, libraries).

    Returns
    -------
    str
        E.g. ``auvtrack 0.1.0 (sources 1a2b3c4d5e6f), Python 3.11.7, NumPy 1.26.4, Numba 0.59.1,
        vector math avx2``; the source digest is the SHA-256 of the package's ``.py`` files.
    """
    import platform

    import numpy as np

    from . import __version__
    from .jit.vecmath import BACKEND

    try:
        import numba

        from .jit import source_hash

        extra = f"Numba {numba.__version__}, vector math {BACKEND}"
        digest = f" (sources {source_hash()[:12]})"
    except ImportError:  # pragma: no cover - numba is a dependency
        extra, digest = f"vector math {BACKEND}", ""
    return f"auvtrack {__version__}{digest}, Python {platform.python_version()}, NumPy {np.__version__}, {extra}"


def _base_scenario() -> tuple[str, str]:
    from .scenario import paper_scenario_path

    return ("Base scenario: the packaged Section 4 scenario (`auvtrack/data/scenarios/paper.toml`); "
            "the runs of this report change it as described above.", paper_scenario_path().read_text())


class Report:
    """A report under construction, written to ``<out>/report.md`` and ``<out>/report.html``.

    Every method adds one :class:`Block`; :meth:`text` renders the blocks as Markdown and
    :meth:`html` as one self-contained HTML page, so the two always hold the same content.
    Both end with a "Scenario and version" section: the scenarios given to :meth:`scenario`
    (by default the packaged Section 4 scenario every study starts from) and :func:`provenance`.

    Parameters
    ----------
    out : pathlib.Path
        Report folder (created on :meth:`write` or :meth:`figure`).
    title : str
        Level-1 heading and page title.
    """

    def __init__(self, out: str | Path, title: str) -> None:
        self.out = Path(out)
        self.title = title
        self.blocks: list[Block] = []
        if _QUICK.get():
            self.paragraph(QUICK_BANNER)
        self.scenarios: list[tuple[str, str]] = []
        self.figures: list[Path] = []

    def heading(self, text: str, level: int = 2) -> None:
        """Add a heading of ``level`` (2 = section)."""
        self.blocks.append(Block("heading", {"text": text, "level": level}))

    def paragraph(self, text: str) -> None:
        """Add a paragraph (Markdown inline markup allowed: code, bold, italics, links)."""
        self.blocks.append(Block("paragraph", {"text": text.strip()}))

    def bullets(self, items: Iterable[str]) -> None:
        """Add a bullet list."""
        self.blocks.append(Block("bullets", {"items": [str(it) for it in items]}))

    def table(self, headers: Sequence[str], rows: Iterable[Sequence[Any]], digits: int = 4) -> None:
        """Add a table; every cell goes through :func:`fmt` (see :func:`markdown_table`)."""
        headers = [str(h) for h in headers]
        cells = []
        for row in rows:
            row = [fmt(c, digits) for c in row]
            if len(row) != len(headers):
                raise ValueError(f"table row has {len(row)} cells, expected {len(headers)}")
            cells.append(row)
        self.blocks.append(Block("table", {"headers": headers, "rows": cells}))

    def markdown(self, text: str) -> None:
        """Add pre-formatted Markdown (e.g. :func:`metrics_table`), verbatim.

        The Markdown file gets it as it is; the HTML page gets it parsed by :func:`markdown_blocks`.
        """
        self.blocks.append(Block("markdown", {"text": text, "blocks": markdown_blocks(text)}))

    def verdicts(self, rows: Iterable[tuple[str, str, str]]) -> None:
        """Add verdicts on claims, one bullet each: ``(claim, verdict, evidence)``.

        The verdict is a word such as ``supported``, ``not supported`` or ``mixed``; the HTML
        page colours it.
        """
        self.blocks.append(Block("verdicts", {"rows": [tuple(str(x) for x in r) for r in rows]}))

    def figure(self, fig: Any, name: str, caption: str = "", dpi: int = 120) -> Path:
        """Save a Matplotlib figure as ``figures/<name>.png`` and add it.

        Build figures with :class:`matplotlib.figure.Figure` (no pyplot, no GUI backend); a
        pyplot figure is closed after saving.  Its fonts are first scaled so that its smallest
        text is readable in the HTML page's figure area (:func:`auvtrack.report_figures.make_readable`).

        Returns
        -------
        pathlib.Path
            The PNG path.
        """
        path = self.out / "figures" / f"{name}.png"
        path.parent.mkdir(parents=True, exist_ok=True)
        text_px = make_readable(fig, dpi)
        fig.savefig(path, dpi=dpi, bbox_inches="tight")
        if "matplotlib.pyplot" in sys.modules:  # a pyplot-managed figure: release it
            sys.modules["matplotlib.pyplot"].close(fig)
        return self.image(path, caption, text_px)

    def image(self, path: str | Path, caption: str = "", text_px: float | None = None) -> Path:
        """Add a PNG file already written inside the report folder (e.g. by a worker process).

        ``text_px`` is the height its smallest text is shown at in the HTML page
        (:func:`auvtrack.report_figures.make_readable` returns it), recorded as ``data-text-px``.

        Returns
        -------
        pathlib.Path
            ``path``.

        Raises
        ------
        ValueError
            If the file is not a PNG inside the report folder.
        """
        path = Path(path)
        try:
            rel = path.resolve().relative_to(self.out.resolve()).as_posix()
        except ValueError:
            raise ValueError(f"figure {path} is outside the report folder {self.out}") from None
        png = path.read_bytes()
        if png[:8] != b"\x89PNG\r\n\x1a\n":
            raise ValueError(f"figure {path} is not a PNG file")
        self.figures.append(path)
        self.blocks.append(Block("figure", {"src": rel, "caption": caption, "name": path.stem, "png": png,
                                            "text_px": text_px}))
        return path

    def scenario(self, text: str | Mapping[str, Any], label: str) -> None:
        """Record a scenario the report's runs use (TOML text, or a mapping shown as JSON).

        Shown in the closing "Scenario and version" section instead of the packaged Section 4
        scenario; call it once per scenario worth showing.
        """
        if not isinstance(text, str):
            text = json.dumps(to_jsonable(text), indent=2)
        self.scenarios.append((label, text.rstrip("\n")))

    def _closing(self) -> list[Block]:
        scenarios = self.scenarios or [_base_scenario()]
        return ([Block("heading", {"text": "Scenario and version", "level": 2}),
                 Block("paragraph", {"text": f"Produced by {provenance()}."})]
                + [Block("code", {"label": label, "text": text}) for label, text in scenarios])

    def text(self, closing: bool = True) -> str:
        """The report as Markdown (what :meth:`write` puts in ``report.md``).

        Parameters
        ----------
        closing : bool, optional
            Include the closing "Scenario and version" section (``False``: for a terminal).

        Returns
        -------
        str
        """
        parts = [f"# {self.title}", ""]
        for b in [*self.blocks, *(self._closing() if closing else [])]:
            parts += _markdown(b)
        return "\n".join(parts).rstrip() + "\n"

    def html(self) -> str:
        """The report as one self-contained HTML page (what :meth:`write` puts in ``report.html``)."""
        from jinja2 import Environment, PackageLoader, StrictUndefined
        from markupsafe import Markup

        env = Environment(loader=PackageLoader("auvtrack", "templates"), autoescape=True,
                          undefined=StrictUndefined, trim_blocks=True, lstrip_blocks=True)
        env.filters["inline"] = lambda s: Markup(inline_html(str(s)))
        env.filters["b64"] = lambda b: base64.b64encode(b).decode("ascii")
        return env.get_template("report.html.j2").render(title=self.title, blocks=[*self.blocks, *self._closing()],
                                                     figure_area_rem=FIGURE_AREA_REM)

    def write(self, name: str = "report.md", html: str | None = "report.html") -> Path:
        """Write ``<out>/<name>`` (Markdown) and ``<out>/<html>`` (HTML, unless None).

        Returns
        -------
        pathlib.Path
            The Markdown file.
        """
        self.out.mkdir(parents=True, exist_ok=True)
        path = self.out / name
        path.write_text(self.text(), encoding="utf-8")
        if html:
            (self.out / html).write_text(self.html(), encoding="utf-8")
        return path


def _markdown(b: Block) -> list[str]:
    d = b.data
    if b.kind == "heading":
        return ["#" * d["level"] + " " + d["text"], ""]
    if b.kind == "paragraph":
        return [d["text"], ""]
    if b.kind == "bullets":
        return [f"- {it}" for it in d["items"]] + [""]
    if b.kind == "table":  # cells are formatted already (fmt escapes "|")
        lines = ["| " + " | ".join(d["headers"]) + " |", "|" + "---|" * len(d["headers"])]
        return lines + ["| " + " | ".join(row) + " |" for row in d["rows"]] + [""]
    if b.kind == "markdown":
        return [d["text"], ""]
    if b.kind == "verdicts":
        return [f"- **{claim}**: {verdict}. {evidence}" for claim, verdict, evidence in d["rows"]] + [""]
    if b.kind == "figure":
        out = [f"![{d['caption'] or d['name']}]({d['src']})", ""]
        return out + ([f"*{d['caption']}*", ""] if d["caption"] else [])
    if b.kind == "code":
        return ([d["label"], ""] if d["label"] else []) + ["```", d["text"], "```", ""]
    raise ValueError(f"unknown report block {b.kind!r}")
