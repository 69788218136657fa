"""The README names the paper it implements and says how to run the tests: the per-test timeout
it quotes is pyproject's, and its fast subset deselects the marker pyproject registers."""
from __future__ import annotations

import re
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
README = (ROOT / "README.md").read_text()
PYTEST = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["pytest"]["ini_options"]


def _words(text: str) -> str:
    return " ".join(text.split())


def test_the_readme_names_the_paper_as_the_errata_do():
    title = re.search(r"The paper auvtrack implements, \*(.+?)\*", _words((ROOT / "docs" / "corrections.md").read_text()))
    assert title and f"*{title.group(1)}*" in _words(README)


def test_the_quoted_timeout_and_fast_subset_are_pyproject_s():
    minutes = int(re.search(r"bounded by a (\d+)-minute timeout", _words(README)).group(1))
    assert minutes * 60 == PYTEST["timeout"]
    command = re.search(r'python -m pytest -m "not (\w+)"', README)
    assert command and any(m.startswith(command.group(1) + ":") for m in PYTEST["markers"])
