"""``auvtrack compare`` compiles before its runs: a bar over the kernels, none under ``--quiet``."""
from __future__ import annotations

import pytest

from auvtrack.cli import main
from auvtrack.engine import kernels
from tiny_suite import TINY

NOTICE = "compiling kernels (first run only, about"


@pytest.fixture
def tiny(tmp_path):
    path = tmp_path / "tiny.toml"
    path.write_text(TINY)
    return path


@pytest.fixture
def uncompiled(monkeypatch):
    """Every kernel reads as not compiled until compiled (loaded from the disk cache) in this test."""
    done: set[str] = set()
    real = kernels.is_compiled
    monkeypatch.setattr(kernels, "is_compiled", lambda key, lanes=False: key.name in done and real(key, lanes))
    monkeypatch.setattr(kernels, "mark_compiled", lambda key, seconds: done.add(key.name))
    return done


@pytest.mark.parametrize("quiet", [False, True])
def test_the_compile_bar_is_shown_unless_quiet(tiny, tmp_path, uncompiled, capsys, quiet):
    args = ["compare", "--suite", str(tiny), "--quick", "--controllers", "pid", "--out", str(tmp_path / "c")]
    assert main([*args, *(["--quiet"] if quiet else [])]) == 0
    err = capsys.readouterr().err
    assert err.count(NOTICE) == 1 and any(n.startswith("k_pid__") for n in uncompiled), err
    bar = err.split(NOTICE, 1)[1]
    assert ("compiling:" in bar) is not quiet, err
