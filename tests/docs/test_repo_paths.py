"""The repository stands alone: no file refers to a path outside it, and its own links resolve.

A user of the repository has only the repository.  Every "ERRATA n" citation therefore points at
the project's own ``docs/corrections.md``, never at the errata file the project was checked
against, and every relative link or path written in a file stays inside the repository.
(Test files may mention outside paths; they are the only exception.)
"""
from __future__ import annotations

import re
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
TEXT_SUFFIXES = {".py", ".md", ".toml", ".txt", ".cfg", ".ini", ".json", ".j2", ".yml", ".yaml", ".sh", ""}
OUTSIDE = re.compile(r"shared/paper|\.\./shared|/work/|ERRATA\.md")
MD_LINK = re.compile(r"\]\(([^)\s]+)\)")
RELATIVE = re.compile(r"(?<![\w.])(\.\./[\w./-]+)")


def _files() -> list[Path]:
    try:
        out = subprocess.run(["git", "ls-files", "-z"], cwd=ROOT, capture_output=True, check=True).stdout
        names = [n for n in out.decode().split("\0") if n]
    except (OSError, subprocess.CalledProcessError):  # not a git checkout: walk the tree
        names = [str(p.relative_to(ROOT)) for p in ROOT.rglob("*") if p.is_file() and ".git" not in p.parts
                 and "__pycache__" not in p.parts]
    return [ROOT / n for n in names if not n.startswith("tests/")]


def _text_files() -> list[Path]:
    return [p for p in _files() if p.suffix in TEXT_SUFFIXES and p.is_file()]


def _inside(path: Path) -> bool:
    try:
        path.resolve().relative_to(ROOT)
        return True
    except ValueError:
        return False


def test_the_scan_sees_the_files_that_used_to_point_outside():
    names = {p.relative_to(ROOT).as_posix() for p in _text_files()}
    assert {"README.md", "docs/corrections.md", "docs/theory.md", "docs/derivation.md",
            "auvtrack/data/scenarios/paper.toml"} <= names


@pytest.mark.parametrize("path", _text_files(), ids=lambda p: p.relative_to(ROOT).as_posix())
def test_no_file_refers_outside_the_repository(path):
    text = path.read_text(encoding="utf-8", errors="replace")
    rel = path.relative_to(ROOT).as_posix()
    bad = [m.group(0) for m in OUTSIDE.finditer(text)]
    assert not bad, f"{rel} refers outside the repository: {bad}"
    for token in RELATIVE.findall(text):
        assert _inside(path.parent / token), f"{rel}: {token} leaves the repository"
    if path.suffix == ".md":
        for target in MD_LINK.findall(text):
            if re.match(r"[a-z]+:|#", target):  # URLs and anchors
                continue
            file = (path.parent / target.split("#")[0]).resolve()
            assert _inside(file) and file.exists(), f"{rel}: link {target} does not resolve inside the repository"


def test_symlinks_stay_inside_the_repository():
    links = [p for p in _files() if p.is_symlink()]
    assert ROOT / "scenarios" / "paper.toml" in links
    for p in links:
        assert _inside(p) and p.resolve().exists(), p


def test_errata_citations_have_their_reference_in_the_repository():
    """Code cites "ERRATA n"; docs/corrections.md has a row n for every number cited."""
    rows = set(re.findall(r"^\| (\d+) \|", (ROOT / "docs" / "corrections.md").read_text(), re.M))
    cited = set()
    for p in _text_files():
        cited |= set(re.findall(r"ERRATA (\d+)", p.read_text(encoding="utf-8", errors="replace")))
    assert cited and cited <= rows, sorted(cited - rows, key=int)
