"""The documented ranges of docs/scenarios.md, parsed from its key tables.

The bad-input tests take their bounds from here, never from the schema they test: loosening a
rule in the code (``sim.dt <= 0.1`` to ``<= 1``) or in the docs alone makes a test fail.

Grammar of an "allowed" cell (the parts that carry numbers; the rest is prose):

* ``> a``, ``>= a``, ``< a``, ``<= a``; ``in (a, b)``, ``in [a, b]``, ``[a, b]`` (bare, at the
  start) and the half-open variants; ``a`` is a number, ``π/2`` or ``2^N``; a comparison with a
  backticked field (``<= `duration```) is a cross-field rule, not a bound;
* ``integer`` marks an integer field;
* ``each`` (or ``N numbers``) applies the bounds to every item of an array;
* ``;``-separated parts starting with ``item i`` or ``items i-j`` apply to those items.

Controller rows are ``\\`key\\` (default, range)`` lists inside one cell.
"""
from __future__ import annotations

import math
import re
from dataclasses import dataclass
from pathlib import Path

DOC = Path(__file__).resolve().parents[1] / "docs" / "scenarios.md"

_NUM = r"(?:-?π/2|2\^\d+|-?(?:\d+(?:\.\d*)?|\.\d+)(?:e[+-]?\d+)?)"
_INTERVAL = re.compile(rf"(?:^|\bin\s*)([\[(])\s*({_NUM})\s*,\s*({_NUM})\s*([\])])")
_CMP = re.compile(rf"(>=|<=|>|<)\s*({_NUM})(?![\w`])")
_ITEMS = re.compile(r"^\s*items?\s+(\d+)(?:-(\d+))?\b")


def number(text: str) -> float | int:
    """Value of a documented number (``π/2``, ``2^53`` and plain literals)."""
    text = text.strip()
    if text.endswith("π/2"):
        return -math.pi / 2 if text.startswith("-") else math.pi / 2
    if text.startswith("2^"):
        return 2 ** int(text[2:])
    value = float(text)
    return int(value) if value.is_integer() and "." not in text and "e" not in text else value


@dataclass(frozen=True)
class Range:
    """Documented bounds of one number: ``lo <(=) x <(=) hi`` (None = unbounded)."""

    path: tuple  # scenario key path, items as ints
    lo: float | None = None
    lo_open: bool = False
    hi: float | None = None
    hi_open: bool = False
    integer: bool = False

    @property
    def dotted(self) -> str:
        return ".".join(str(p) for p in self.path)

    def inside(self, x: float) -> bool:
        if self.lo is not None and (x <= self.lo if self.lo_open else x < self.lo):
            return False
        if self.hi is not None and (x >= self.hi if self.hi_open else x > self.hi):
            return False
        return True


def _bounds(text: str) -> dict:
    b: dict = {}
    for m in _INTERVAL.finditer(text):
        b.update(lo=number(m.group(2)), lo_open=m.group(1) == "(", hi=number(m.group(3)), hi_open=m.group(4) == ")")
    for m in _CMP.finditer(text):
        op, v = m.group(1), number(m.group(2))
        if op.startswith(">"):
            b.update(lo=v, lo_open=op == ">")
        else:
            b.update(hi=v, hi_open=op == "<")
    return b


def _ranges_of_cell(path: tuple, cell: str, n_items: int | None) -> list[Range]:
    integer = re.search(r"\binteger\b(?!\s+multiple)", cell) is not None
    out = []
    for part in cell.split(";"):
        b = _bounds(part)
        if not b:
            continue
        m = _ITEMS.match(part)
        if m:
            lo, hi = int(m.group(1)), int(m.group(2) or m.group(1))
            items = range(lo, hi + 1)
        elif n_items is not None:
            items = range(n_items)
        else:
            items = None
        if items is None:
            out.append(Range(path, integer=integer, **b))
        else:
            out += [Range(path + (i,), integer=integer, **b) for i in items]
    return out


def _split_row(line: str) -> list[str]:
    return [c.strip() for c in line.strip().strip("|").split("|")]


def _tables(text: str):
    """Yield (section heading, header cells, rows) for every Markdown table."""
    heading, lines = "", text.splitlines()
    i = 0
    while i < len(lines):
        line = lines[i]
        if line.startswith("#"):
            heading = line.lstrip("#").strip()
        if line.startswith("|") and i + 1 < len(lines) and set(lines[i + 1].replace("|", "").strip()) <= set("-: "):
            header = _split_row(line)
            rows = []
            i += 2
            while i < len(lines) and lines[i].startswith("|"):
                rows.append(_split_row(lines[i]))
                i += 1
            yield heading, header, rows
            continue
        i += 1


def _section(heading: str) -> str | None:
    if heading == "Top level":
        return ""
    m = re.match(r"^`\[(\w+)\]`", heading)
    return m.group(1) if m else None


def _controller_ranges(cell_kind: str, cell: str) -> list[Range]:
    """``\\`key\\` (default, range)`` items of a controller row, parentheses matched."""
    out = []
    for m in re.finditer(r"`(\w+)` \(", cell):
        depth, j = 1, m.end()
        while j < len(cell) and depth:
            depth += {"(": 1, ")": -1}.get(cell[j], 0)
            j += 1
        inner = cell[m.end():j - 1]
        _, _, rng = inner.partition(", ")
        out += _ranges_of_cell(("controller", m.group(1)), rng, None)
    return out


def documented_ranges(base: dict) -> dict[str, list[Range]]:
    """Every documented numeric range, grouped by controller kind ("" for the other sections).

    Parameters
    ----------
    base : dict
        A resolved scenario (``to_dict()``): it tells which keys are arrays and their lengths.
    """
    out: dict[str, list[Range]] = {"": []}
    for heading, header, rows in _tables(DOC.read_text(encoding="utf-8")):
        section = _section(heading)
        if section is None:
            continue
        if section == "controller":
            for row in rows:
                kind = row[0].strip("`")
                out.setdefault(kind, []).extend(_controller_ranges(kind, row[1]))
            continue
        if "allowed" not in header:
            continue
        col = header.index("allowed")
        for row in rows:
            key = row[0].strip("`")
            if not re.fullmatch(r"\w+", key):
                continue
            path = (section, key) if section else (key,)
            node = base
            for p in path:
                node = node.get(p) if isinstance(node, dict) else None
            n_items = len(node) if isinstance(node, list) else None
            out[""] += _ranges_of_cell(path, row[col], n_items)
    return out


def limits_defaults() -> dict[str, int]:
    """``[limits]`` key -> documented default (the ``default`` column, ``_`` separators allowed)."""
    for heading, header, rows in _tables(DOC.read_text(encoding="utf-8")):
        if heading.startswith("`[limits]`"):
            col = header.index("default")
            return {row[0].strip("`"): int(row[col].strip("`").replace("_", "")) for row in rows}
    raise AssertionError("docs/scenarios.md has no [limits] table")
