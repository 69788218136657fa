"""Seed splits of a suite: training, validation and evaluation seed indices are disjoint, declared in
the file, and a tuning can ask which split an index belongs to."""
from __future__ import annotations

from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from auvtrack.benchmark.suite import SPLITS, SuiteError, available_suites, load_suite
from test_suite_validation import TINY


def _load(tmp_path: Path, text: str):
    path = tmp_path / "s.toml"
    path.write_text(text)
    return load_suite(path, check=False)


def _refused(tmp_path: Path, text: str) -> str:
    path = tmp_path / "bad.toml"
    path.write_text(text)
    with pytest.raises(SuiteError) as info:
        load_suite(path, check=False)
    msg = str(info.value)
    assert "\n" not in msg and msg.startswith(f"{path}: "), msg
    return msg[len(f"{path}: "):]


@pytest.mark.parametrize("name", available_suites())
def test_every_shipped_suite_keeps_its_splits_disjoint(name):
    suite = load_suite(name, check=False)
    sets = {s: set(suite.split_seeds(s)) for s in SPLITS if s == "evaluation" or getattr(suite.file.splits, s)}
    assert "training" in sets, f"{name} declares no training split"
    full = set(range(suite.file.seeds))
    assert sets["evaluation"] == full
    names = list(sets)
    for i, a in enumerate(names):
        for b in names[i + 1:]:
            assert not sets[a] & sets[b], (name, a, b)
    for s, idx in sets.items():
        assert all(suite.split_of(i) == s for i in idx)
    quick = suite.quick_variant()
    assert set(quick.split_seeds("evaluation")) <= full  # --quick evaluates on evaluation seeds only


def test_splits_do_not_change_the_comparison(tmp_path):
    plain = _load(tmp_path, TINY)
    split = _load(tmp_path, TINY + "[splits.training]\nseeds = [10, 20]\ntiers = [\"calm\"]\n")
    assert plain.fingerprint() == split.fingerprint()
    assert split.split_cells("training") == [("helix", "calm"), ("line", "calm")]
    assert split.split_cells("evaluation") == plain.split_cells("evaluation")
    with pytest.raises(SuiteError, match=r"splits\.validation: not declared"):
        split.split_seeds("validation")
    with pytest.raises(SuiteError, match="split: must be one of training, validation, evaluation"):
        split.split_seeds("test")


@pytest.mark.parametrize("extra, expect", [
    ("[splits.training]\nseeds = [0, 5]\n", r"splits\.training\.seeds: \[0, 5\) overlaps the evaluation seeds \[0, 3\)"),
    ("[splits.training]\nseeds = [10, 20]\n[splits.validation]\nseeds = [15, 30]\n",
     r"splits\.validation\.seeds: \[15, 30\) overlaps the training seeds \[10, 20\)"),
    ("[splits.training]\nseeds = [10, 10]\n", r"splits\.training.*start < stop"),
    ("[splits.training]\nseeds = [10, 20]\ntasks = [\"circle\"]\n", r"splits\.training\.tasks: unknown task 'circle'"),
    ("[splits.training]\nseeds = [10, 20]\ntiers = [\"ocean\"]\n", r"splits\.training\.tiers: unknown tier 'ocean'"),
    ("[splits.testing]\nseeds = [10, 20]\n", r"splits\.testing"),
    ("[splits.training]\nseeds = [-1, 2]\n", r"splits\.training\.seeds"),
])
def test_a_bad_split_is_one_line_naming_it(tmp_path, extra, expect):
    import re
    msg = _refused(tmp_path, TINY + extra)
    assert re.search(expect, msg), msg


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 40), st.integers(1, 20), st.integers(0, 40), st.integers(1, 20))
def test_overlap_is_refused_exactly_when_the_ranges_meet(a, na, b, nb):
    text = TINY + f"[splits.training]\nseeds = [{a + 3}, {a + 3 + na}]\n[splits.validation]\nseeds = [{b + 3}, {b + 3 + nb}]\n"
    meet = a < b + nb and b < a + na
    import tempfile
    with tempfile.TemporaryDirectory() as d:
        path = Path(d) / "s.toml"
        path.write_text(text)
        if meet:
            with pytest.raises(SuiteError, match="overlaps the training seeds"):
                load_suite(path, check=False)
        else:
            s = load_suite(path, check=False)
            assert not set(s.split_seeds("training")) & set(s.split_seeds("validation"))
