"""``auvtrack compare`` compiles before its runs: a notice and a bar over the kernels, neither under ``--quiet``."""
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
def test_the_compile_notice_and_bar_are_shown_unless_quiet(tiny, tmp_path, uncompiled, capsys, quiet):
    args = ["compare", "--suite", str(tiny), "--quick", "--controllers", "pid", "--out", str(tmp_path / "c")]
    assert main([*args, *(["--quiet"] if quiet else [])]) == 0
    err = capsys.readouterr().err
    assert any(n.startswith("k_pid__") for n in uncompiled), uncompiled  # compiled (loaded) either way
    if quiet:  # as tune --quiet and train --quiet: neither the notice nor the bar
        assert err.strip() == "", err
    else:
        assert err.count(NOTICE) == 1 and "compiling:" in err.split(NOTICE, 1)[1], err
    assert main([*args, "--out", str(tmp_path / "quiet"), "--quiet"]) == 0
    err = capsys.readouterr().err
    assert err.strip() == "", err
