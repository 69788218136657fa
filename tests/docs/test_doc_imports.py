"""Every ``import auvtrack...`` and ``from auvtrack... import ...`` in the README's and docs' code blocks resolves.

A reader copies these lines; a module moved or a name renamed must change the docs with it.
"""
from __future__ import annotations

import ast
import importlib
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
DOCS = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
FENCE = re.compile(r"^\s*(```|~~~)")
START = re.compile(r"^(?:>>> |\.\.\. )?\s*(from\s+auvtrack[\w.]*\s+import\b.*|import\s+auvtrack[\w.]*.*)$")


def doc_imports(text: str) -> list[tuple[int, str]]:
    """(line number, statement) of every auvtrack import inside a fenced code block of a Markdown text.

    Parameters
    ----------
    text : str
        A Markdown document.

    Returns
    -------
    list of (int, str)
        The 1-based line of each import and its source, continuation lines of a parenthesised
        name list joined, trailing comments dropped.
    """
    found, in_block, pending, first = [], False, None, 0
    for no, line in enumerate(text.splitlines(), 1):
        if FENCE.match(line):
            in_block, pending = not in_block, None
            continue
        if not in_block:
            continue
        body = re.sub(r"^(>>> |\.\.\. )", "", line).split("#", 1)[0].rstrip()
        if pending is not None:
            pending += " " + body.strip()
        else:
            m = START.match(line.split("#", 1)[0].rstrip())
            if not m:
                continue
            pending, first = m.group(1), no
        if pending.count("(") == pending.count(")") and not pending.endswith("\\"):
            found.append((first, pending))
            pending = None
    return found


def _cases():
    for path in DOCS:
        for no, stmt in doc_imports(path.read_text()):
            yield pytest.param(stmt, id=f"{path.relative_to(ROOT)}:{no}")


def resolve(stmt: str) -> None:
    """Import what ``stmt`` imports; AssertionError naming what does not exist.

    Parameters
    ----------
    stmt : str
        One ``import`` or ``from ... import`` statement.
    """
    node = ast.parse(stmt).body[0]
    if isinstance(node, ast.Import):
        for alias in node.names:
            importlib.import_module(alias.name)
        return
    assert isinstance(node, ast.ImportFrom) and node.module, stmt
    module = importlib.import_module(node.module)
    for alias in node.names:
        if alias.name == "*" or hasattr(module, alias.name):
            continue
        try:
            importlib.import_module(f"{node.module}.{alias.name}")
        except ModuleNotFoundError:
            raise AssertionError(f"{node.module} has no {alias.name!r}") from None


CASES = list(_cases())


def test_the_docs_show_imports():
    assert len(CASES) >= 10


@pytest.mark.parametrize("stmt", CASES)
def test_doc_import_resolves(stmt):
    resolve(stmt)


def test_a_wrong_name_is_caught():
    text = "```python\nfrom auvtrack.engine.loop import (run,\n    no_such_thing)\nimport auvtrack.no_such_module\n```\n"
    found = doc_imports(text)
    assert found == [(2, "from auvtrack.engine.loop import (run, no_such_thing)"), (4, "import auvtrack.no_such_module")]
    with pytest.raises(AssertionError, match="no_such_thing"):
        resolve(found[0][1])
    with pytest.raises(ModuleNotFoundError):
        resolve(found[1][1])


def test_imports_outside_code_blocks_are_not_read():
    assert doc_imports("from auvtrack import nothing_here\n\n```toml\nkey = 1\n```\n") == []
