"""Bounded reading: no file, override or dict crashes, hangs or fills the memory; each refusal is one line.

The hostile inputs of the hardening issue (keys and arrays nested 3000-20 000 levels, ``/dev/zero``,
a FIFO, a directory, a huge file) through the library and through ``check`` and ``run``, which
must refuse them with the same line; and the bounds themselves, from both sides.
"""
from __future__ import annotations

import json
import math
import os
import re
import sys
import threading
import tomllib
from pathlib import Path

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

from auvtrack.scenario import ScenarioError, load_scenario, read_toml
from auvtrack.scenario import reading
from auvtrack.scenario.overrides import parse_overrides
from auvtrack.scenario.reading import MAX_FILE_BYTES, MAX_NESTING, check_nesting, check_text_nesting, read_bounded

ROOT = Path(__file__).resolve().parents[2]
PAPER = ROOT / "scenarios" / "paper.toml"
DEEP = [3000, 20_000]


def one_line(exc: BaseException) -> str:
    text = str(exc)
    assert "\n" not in text and "\r" not in text, text
    return text


# --- files: type and size, before reading -----------------------------------------------------

def test_a_directory_is_refused(tmp_path):
    with pytest.raises(ScenarioError, match=r": is a directory, not a TOML file"):
        read_toml(tmp_path)


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="no FIFOs on this platform")
def test_a_fifo_is_refused_without_blocking(tmp_path):
    """Opening a FIFO for reading blocks until a writer comes; the reader must not wait for one."""
    fifo = tmp_path / "s.toml"
    os.mkfifo(fifo)
    box: dict = {}

    def target():
        try:
            read_toml(fifo)
        except ScenarioError as exc:
            box["msg"] = one_line(exc)

    th = threading.Thread(target=target, daemon=True)
    th.start()
    th.join(60)
    if th.is_alive():  # unblock the reader so that the test process can end, then fail
        with open(fifo, "wb"):
            pass
        pytest.fail("reading a FIFO blocked")
    assert box["msg"] == f"{fifo}: is a FIFO (named pipe), not a TOML file (a regular file is needed)"


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="no FIFOs on this platform")
def test_a_fifo_swapped_in_after_the_type_check_is_refused_without_blocking(tmp_path, monkeypatch):
    """The second check, on the descriptor opened non-blocking: the path's type as first seen is a
    regular file (a stand-in for a file replaced by a FIFO in between), the descriptor's a FIFO."""
    fifo = tmp_path / "s.toml"
    os.mkfifo(fifo)
    regular = os.stat(__file__)
    real_stat = os.stat
    monkeypatch.setattr(reading.os, "stat", lambda p, *a, **k: regular if str(p) == str(fifo) else real_stat(p, *a, **k))
    box: dict = {}

    def target():
        try:
            read_toml(fifo)
        except ScenarioError as exc:
            box["msg"] = one_line(exc)

    th = threading.Thread(target=target, daemon=True)
    th.start()
    th.join(60)
    if th.is_alive():
        with open(fifo, "wb"):
            pass
        pytest.fail("opening a FIFO blocked")
    assert box["msg"] == f"{fifo}: is a FIFO (named pipe), not a TOML file (a regular file is needed)"


@pytest.mark.parametrize("device", ["/dev/zero", "/dev/null", "/dev/urandom"])
def test_a_device_is_refused_unread(device, monkeypatch):
    if not os.path.exists(device):
        pytest.skip(f"no {device}")
    monkeypatch.setattr(reading.os, "open", lambda *a: pytest.fail("a device was opened"))
    with pytest.raises(ScenarioError) as info:
        read_toml(device)
    assert one_line(info.value) == f"{device}: is a character device, not a TOML file (a regular file is needed)"


def test_a_file_over_the_bound_is_refused_unread(tmp_path, monkeypatch):
    """A sparse file one byte over the bound: refused from its size, not one byte read."""
    big = tmp_path / "big.toml"
    with open(big, "wb") as fh:
        fh.truncate(MAX_FILE_BYTES + 1)
    monkeypatch.setattr(reading.os, "read", lambda *a: pytest.fail("the file was read"))
    with pytest.raises(ScenarioError) as info:
        read_toml(big)
    assert one_line(info.value) == (f"{big}: is {MAX_FILE_BYTES + 1} bytes, more than the {MAX_FILE_BYTES} bytes "
                                    f"({MAX_FILE_BYTES / 2 ** 20:g} MiB) a TOML file may have")


@given(size=st.integers(0, 300), limit=st.integers(0, 300))
@settings(max_examples=60, deadline=None)
def test_the_size_bound_is_exact(tmp_path_factory, size, limit):
    """A file of ``limit`` bytes is read whole, one of ``limit + 1`` is refused."""
    path = tmp_path_factory.mktemp("size") / "f.toml"
    data = bytes(range(256)) * 2
    path.write_bytes(data[:size])
    if size <= limit:
        assert read_bounded(path, limit=limit) == data[:size]
    else:
        with pytest.raises(ScenarioError, match=rf"is {size} bytes, more than the {limit} bytes"):
            read_bounded(path, limit=limit)


def test_missing_files_and_bad_paths_are_one_line(tmp_path):
    with pytest.raises(ScenarioError, match=r"^nope\.toml: file not found$"):
        read_toml("nope.toml")
    with pytest.raises(ScenarioError) as info:
        read_toml(str(tmp_path / "a\0b.toml"))
    assert "NUL" in one_line(info.value)


# --- nesting: text, overrides, dicts ------------------------------------------------------------

def _nested(depth: int, kind: str) -> str:
    if kind == "array":
        return "[" * depth + "]" * depth
    if kind == "table":
        return "{a = " * depth + "1" + "}" * depth
    return "[{a = " * (depth // 2) + "1" + "}]" * (depth // 2)


@pytest.mark.parametrize("depth", DEEP)
@pytest.mark.parametrize("kind", ["array", "table", "mixed"])
def test_deeply_nested_files_are_one_line(tmp_path, depth, kind):
    path = tmp_path / "deep.toml"
    path.write_text(f'name = "x"\n\nv = {_nested(depth, kind)}\n')
    with pytest.raises(ScenarioError) as info:
        load_scenario(path)
    assert one_line(info.value) == (f"{path}: nested more than {MAX_NESTING} levels deep "
                                    "(arrays and inline tables; line 3)")


@pytest.mark.parametrize("depth", DEEP)
@pytest.mark.parametrize("form", ["key", "header", "quoted"])
def test_long_dotted_keys_in_files_are_one_line(tmp_path, depth, form):
    part = '"a.b"' if form == "quoted" else "a"
    key = ".".join([part] * depth)
    text = f"[{key}]\nx = 1\n" if form == "header" else f"{key} = 1\n"
    path = tmp_path / "deep.toml"
    path.write_text(text)
    with pytest.raises(ScenarioError) as info:
        read_toml(path)
    assert one_line(info.value) == f"{path}: a dotted key of more than {MAX_NESTING} parts (line 1)"


@pytest.mark.parametrize("depth", DEEP)
@pytest.mark.parametrize("kind", ["array", "table"])
def test_deep_override_values_are_one_line(depth, kind):
    with pytest.raises(ScenarioError) as info:
        load_scenario({}, [f"initial.eta={_nested(depth, kind)}"])
    assert f"nested more than {MAX_NESTING} levels deep" in one_line(info.value)


@pytest.mark.parametrize("depth", DEEP)
def test_deep_override_keys_are_one_line(depth):
    key = ".".join(["sim"] * depth)
    with pytest.raises(ScenarioError) as info:
        load_scenario({}, [f"{key}=1"])
    assert f"a key of more than {MAX_NESTING} parts (got {depth})" in one_line(info.value)
    with pytest.raises(ScenarioError):
        load_scenario({}, {key: 1})


def _deep_dict(depth: int, leaf=1):
    node = leaf
    for _ in range(depth):
        node = {"a": node}
    return node


@pytest.mark.parametrize("depth", DEEP)
def test_deep_dicts_and_lists_are_one_line(depth):
    with pytest.raises(ScenarioError) as info:
        load_scenario({"sim": _deep_dict(depth)})
    assert one_line(info.value) == (f"<dict>: sim: nested more than {MAX_NESTING} levels deep (tables and arrays; "
                                    "or a table that contains itself)")
    deep_list: list = []
    for _ in range(depth):
        deep_list = [deep_list]
    with pytest.raises(ScenarioError, match="nested more than"):
        load_scenario({}, {"initial.eta": deep_list})


def test_a_dict_that_contains_itself_is_one_line():
    d: dict = {"kind": "helix"}
    d["self"] = d
    with pytest.raises(ScenarioError, match="or a table that contains itself"):
        load_scenario({"reference": d})


def _toml_value(depth: int, draw_kind) -> tuple[str, object]:
    """TOML text and the Python value of a nesting of exactly ``depth`` arrays / inline tables."""
    text, value = "1", 1
    for kind in draw_kind:
        text, value = (f"[{text}]", [value]) if kind else (f"{{a = {text}}}", {"a": value})
    return text, value


@given(kinds=st.lists(st.booleans(), min_size=0, max_size=2 * MAX_NESTING))
@example(kinds=[True] * (MAX_NESTING - 1))
@example(kinds=[False] * MAX_NESTING)
@example(kinds=[True, False] * (MAX_NESTING // 2) + [True])
@settings(max_examples=120, deadline=None)
def test_the_nesting_bound_is_exact(kinds):
    """Up to MAX_NESTING levels in the value (one more with the document's own table) parse to the
    same value as tomllib gives; one level more is refused."""
    text, value = _toml_value(len(kinds), kinds)
    doc = f"v = {text}"
    if len(kinds) + 1 <= MAX_NESTING:
        check_text_nesting(doc, "t")
        parsed = tomllib.loads(doc)
        check_nesting(parsed, "t")
        assert parsed["v"] == value
    else:
        with pytest.raises(ScenarioError):
            check_text_nesting(doc, "t") if len(kinds) > MAX_NESTING else check_nesting(tomllib.loads(doc), "t")


_NOISE = st.text(alphabet="[]{}.\"'#\\ab\n", max_size=40)


@given(noise=_NOISE.filter(lambda t: "\n" not in t))
@settings(max_examples=150, deadline=None)
def test_brackets_and_dots_in_strings_and_comments_do_not_count(noise):
    """Whatever a string or a comment holds, the scan accepts what tomllib parses as a shallow document."""
    literal = "'''" + noise.replace("'", "") + "'''"
    doc = f"a = {literal}\nb = 1 # {noise}\nc = {json.dumps(noise)}\n"
    try:
        parsed = tomllib.loads(doc)
    except tomllib.TOMLDecodeError:
        return
    check_text_nesting(doc, "t")
    assert parsed["b"] == 1


@given(parts=st.lists(st.from_regex(r"\A[a-z0-9_\-]{1,4}\Z") | st.from_regex(r'\A"[a-z.\[\]]{0,4}"\Z'),
                      min_size=1, max_size=2 * MAX_NESTING))
@example(parts=["a"] * MAX_NESTING)
@example(parts=["a"] * (MAX_NESTING + 1))
@example(parts=['"x.y"'] * MAX_NESTING)
@settings(max_examples=120, deadline=None)
def test_the_dotted_key_bound_is_exact(parts):
    doc = f"{'.'.join(parts)} = 1\n"
    if len(parts) <= MAX_NESTING:
        check_text_nesting(doc, "t")
    else:
        with pytest.raises(ScenarioError, match=f"more than {MAX_NESTING} parts"):
            check_text_nesting(doc, "t")


def test_every_packaged_toml_file_is_inside_the_bounds():
    files = sorted((ROOT / "auvtrack" / "data").rglob("*.toml"))
    assert len(files) > 5
    for f in files:
        read_toml(f)


def test_the_documented_bounds_are_the_constants():
    """docs/scenarios.md and the README state the bounds of reading.py."""
    doc = (ROOT / "docs" / "scenarios.md").read_text()
    readme = (ROOT / "README.md").read_text()
    mib = f"{MAX_FILE_BYTES / 2 ** 20:g} MiB"
    assert f"**`MAX_FILE_BYTES`** bytes ({mib}" in doc and f"**`MAX_NESTING`** levels deep ({MAX_NESTING})" in doc
    assert f"over {mib} or input nested over {MAX_NESTING} levels" in " ".join(readme.split())


def test_the_documented_messages_are_what_the_code_says(tmp_path, monkeypatch):
    """The example lines of docs/scenarios.md ("Reading") come from these calls."""
    doc = " ".join((ROOT / "docs" / "scenarios.md").read_text().split())
    monkeypatch.chdir(tmp_path)
    with open("big.toml", "wb") as fh:
        fh.truncate(20 * 2 ** 20)
    Path("deep.toml").write_text("# a file\n\nv = " + "[" * 40 + "]" * 40 + "\n")
    for path in ("big.toml", "/dev/zero", "deep.toml"):
        if not os.path.exists(path):
            continue
        with pytest.raises(ScenarioError) as info:
            read_toml(path)
        assert f"`{one_line(info.value)}`" in doc, one_line(info.value)


# --- overrides and dicts from Python: what is accepted, what is refused --------------------------

def test_a_plain_string_is_one_override_and_none_is_none():
    assert load_scenario(PAPER, "sim.duration=5") == load_scenario(PAPER, ["sim.duration=5"])
    assert load_scenario(PAPER, None) == load_scenario(PAPER, []) == load_scenario(PAPER)


def test_simulate_takes_the_same_overrides(monkeypatch):
    """``simulate``'s overrides are ``load_scenario``'s (the run itself stubbed out)."""
    import auvtrack
    from auvtrack.simulation import pipeline

    monkeypatch.setattr(pipeline, "run_prepared", lambda prep: prep.scenario)
    assert auvtrack.simulate("paper", "sim.duration=5", warn=False).sim.duration == 5.0
    assert auvtrack.simulate("paper", None, warn=False) == load_scenario(PAPER)
    assert auvtrack.simulate("paper", {"seed": np.int64(4)}, warn=False).seed == 4
    with pytest.raises(ScenarioError, match="the value is None"):
        auvtrack.simulate("paper", {"sim.duration": None}, warn=False)


@pytest.mark.parametrize("overrides", [{"sim.dt=0.002"}, b"sim.dt=0.002", np.array(["sim.dt=0.002"]),
                                       frozenset(), 3, (s for s in ["sim.dt=0.002"])])
def test_overrides_of_another_type_are_one_line(overrides):
    with pytest.raises(ScenarioError) as info:
        load_scenario(PAPER, overrides)
    assert one_line(info.value).startswith("overrides: must be a list of 'dotted.key=value' strings")


_DTYPES = [np.int8, np.int16, np.int32, np.int64, np.uint8, np.uint32, np.uint64]


@given(value=st.integers(0, 127), dtype=st.sampled_from(_DTYPES))
@settings(max_examples=60, deadline=None)
def test_numpy_integers_are_the_integers_they_hold(value, dtype):
    assert load_scenario({}, {"seed": dtype(value)}) == load_scenario({}, {"seed": value})
    assert load_scenario({"seed": dtype(value)}) == load_scenario({"seed": value})


@given(value=st.floats(-0.9, 2.0), dtype=st.sampled_from([np.float16, np.float32, np.float64]))
@settings(max_examples=60, deadline=None)
def test_numpy_floats_are_the_floats_they_hold(value, dtype):
    x = dtype(value)
    if not -0.9 <= float(x) <= 2.0:  # rounding to the dtype may leave the range
        return
    sc = load_scenario({}, {"uncertainty.C": x})
    assert sc.uncertainty.C == float(x) and type(sc.uncertainty.C) is float
    assert sc == load_scenario({}, {"uncertainty.C": float(x)})


@given(eta=st.lists(st.floats(-100, 100), min_size=5, max_size=5).map(lambda v: v[:3] + [0.01, v[4]]),
       dtype=st.sampled_from([np.float32, np.float64]))
@settings(max_examples=40, deadline=None)
def test_numpy_arrays_are_the_lists_they_hold(eta, dtype):
    arr = np.asarray(eta, dtype=dtype)
    as_list = arr.tolist()
    assert load_scenario({}, {"initial.eta": arr}) == load_scenario({}, {"initial.eta": as_list})
    assert load_scenario({"initial": {"eta": arr}}) == load_scenario({"initial": {"eta": as_list}})
    assert load_scenario({}, {"initial.eta": arr}).initial.eta == tuple(as_list)


def test_numpy_bools_and_nested_arrays():
    assert load_scenario({}, {"output.mat": np.bool_(True)}).output.mat is True
    pts = np.array([[0.0, 0.0, 0.0], [10.0, 0.0, 0.0], [20.0, 5.0, 0.0]])
    a = load_scenario({}, {"reference": {"kind": "waypoints", "points": pts}})
    b = load_scenario({}, {"reference": {"kind": "waypoints", "points": pts.tolist()}})
    assert a == b


@pytest.mark.parametrize("value, what", [(None, "None (TOML has no null"), ({1, 2}, "a set"),
                                          (1 + 2j, "a complex"), (b"x", "a bytes"), (object(), "a object"),
                                          ([1.0, None], "None (TOML has no null")])
def test_values_that_are_not_toml_values_are_one_line(value, what):
    with pytest.raises(ScenarioError) as info:
        parse_overrides({"sim.duration": value})
    assert one_line(info.value).startswith(f"override 'sim.duration': the value is {what}")


def test_the_override_text_shows_the_converted_value():
    (ov,) = parse_overrides({"seed": np.int64(3)})
    assert ov.text == "seed=3" and type(ov.value) is int


# --- the roll limit: refused like the pitch limit -------------------------------------------------

SIX = ["plant.model=6dof", "vehicle.preset=remus100"]


@given(phi=st.floats(-math.pi / 2, math.pi / 2, exclude_min=True, exclude_max=True),
       limit=st.floats(0, 180, exclude_min=True))
@settings(max_examples=120, deadline=None)
def test_a_start_beyond_the_roll_limit_is_refused(phi, limit):
    try:
        sc = load_scenario({}, [*SIX, f"initial.phi={phi!r}", f"sim.phi_limit={limit!r}"])
    except ScenarioError as exc:
        assert abs(phi) >= math.radians(limit), one_line(exc)
        assert one_line(exc).startswith(f"<dict>: initial.phi: abs(phi) must be < sim.phi_limit = {limit:g} deg")
    else:
        assert abs(sc.initial.phi) < math.radians(sc.sim.phi_limit)


def test_the_roll_and_pitch_limits_are_refused_alike():
    for key, limit, start in (("theta", "theta_limit", "initial.eta.3"), ("phi", "phi_limit", "initial.phi")):
        with pytest.raises(ScenarioError, match=rf"{re.escape(start)}: abs\({key}\) must be < sim\.{limit} = 10 deg"):
            load_scenario({}, [*SIX, f"sim.{limit}=10", f"{start}=0.2"])


# --- the command line: check and run refuse the same inputs with the same line -------------------

class _Reached(Exception):
    """Raised instead of simulating: validation passed."""


def _cli(args) -> tuple[object, str]:
    import contextlib
    import io
    from unittest import mock

    from auvtrack.cli import main

    err = io.StringIO()
    with mock.patch("auvtrack.simulation.pipeline.run_prepared", side_effect=_Reached), \
            contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
        try:
            code = main(args)
        except _Reached:
            code = "reached the simulation"
    return code, err.getvalue()


def _hostile(tmp: Path) -> list[tuple[str, list[str]]]:
    """(scenario argument, --set arguments) of each hostile input."""
    deep = tmp / "deep.toml"
    deep.write_text("v = " + "[" * 20_000 + "]" * 20_000 + "\n")
    dotted = tmp / "dotted.toml"
    dotted.write_text(".".join(["a"] * 20_000) + " = 1\n")
    big = tmp / "big.toml"
    with open(big, "wb") as fh:
        fh.truncate(MAX_FILE_BYTES + 1)
    bigint = tmp / "bigint.toml"
    bigint.write_text("seed = " + "9" * (sys.get_int_max_str_digits() + 1) + "\n")
    module = tmp / "module.toml"
    module.write_text(f'[controller]\nkind = "plugin"\nmodule = "{"a" * 5000}.py"\n')
    cases = [(str(deep), []), (str(dotted), []), (str(big), []), (str(tmp), []), (str(bigint), []), (str(module), []),
             (str(PAPER), ["--set", "seed=" + "9" * (sys.get_int_max_str_digits() + 1)]),
             (str(PAPER), ["--set", "initial.eta=" + "[" * 3000 + "]" * 3000]),
             (str(PAPER), ["--set", ".".join(["sim"] * 3000) + "=1"]),
             (str(PAPER), ["--set", "plant.model=6dof", "--set", "vehicle.preset=remus100",
                           "--set", "sim.phi_limit=10", "--set", "initial.phi=0.5"]),
             ("bogus", []), ("/dev/zero", [])]
    if hasattr(os, "mkfifo"):
        fifo = tmp / "fifo.toml"
        os.mkfifo(fifo)
        cases.append((str(fifo), []))
    return cases


def test_check_and_run_refuse_hostile_input_with_the_same_line(tmp_path):
    for scenario, sets in _hostile(tmp_path):
        if scenario == "/dev/zero" and not os.path.exists(scenario):
            continue
        run_code, run_err = _cli(["run", scenario, *sets, "--out", str(tmp_path / "out")])
        check_code, check_err = _cli(["check", scenario, *sets])
        assert run_code == 2 and check_code == 2, (scenario, run_code, check_code, run_err)
        assert run_err == check_err and run_err.count("\n") == 1, (run_err, check_err)
        assert run_err.startswith("auvtrack: error: ") and "Traceback" not in run_err
    assert not (tmp_path / "out").exists()


def test_the_console_script_refuses_a_deep_file_without_a_traceback(tmp_path):
    import subprocess

    deep = tmp_path / "deep.toml"
    deep.write_text("v = " + "{a = " * 20_000 + "1" + "}" * 20_000 + "\n")
    p = subprocess.run([sys.executable, "-m", "auvtrack.cli", "check", str(deep)], capture_output=True, text=True,
                       cwd=tmp_path, env={**os.environ, "PYTHONPATH": str(ROOT)}, timeout=300)
    assert p.returncode == 2 and p.stderr.count("\n") == 1 and "Traceback" not in p.stderr, p.stderr
    assert "nested more than" in p.stderr


def test_the_longest_waypoint_list_fits_the_file_bound(tmp_path):
    """The size bound leaves room for the largest ``reference.points`` the spline accepts, every
    coordinate written with the most digits a float can need."""
    from auvtrack.reference.spline import _MAX_POINTS
    from auvtrack.scenario.toml_writer import dumps

    x = -1.2345678901234567e-100  # 24 characters: no float's repr is longer
    assert len(repr(x)) == 24
    doc = {"reference": {"kind": "waypoints", "points": [[x, x, x]] * _MAX_POINTS}}
    path = tmp_path / "long.toml"
    path.write_text(dumps(doc))
    assert path.stat().st_size <= MAX_FILE_BYTES
    assert len(read_toml(path)["reference"]["points"]) == _MAX_POINTS


def test_values_python_cannot_hold_are_one_line(tmp_path):
    """An integer literal over Python's digit limit, in a file and in an override."""
    digits = "9" * (sys.get_int_max_str_digits() + 1)
    path = tmp_path / "s.toml"
    path.write_text(f"seed = {digits}\n")
    with pytest.raises(ScenarioError) as info:
        load_scenario(path)
    assert one_line(info.value).startswith(f"{path}: TOML value error: ")
    with pytest.raises(ScenarioError) as info:
        load_scenario({}, [f"seed={digits}"])
    assert "is not a value Python can hold" in one_line(info.value) and len(str(info.value)) < 600


def test_long_values_are_shortened_in_messages(tmp_path):
    long = "a" * 5000
    with pytest.raises(ScenarioError) as info:
        load_scenario({}, [f"name={long}"])
    assert len(one_line(info.value)) < 400 and "(set by override 'name=aaa" in str(info.value)
    path = tmp_path / "s.toml"
    path.write_text(f'[controller]\nkind = "plugin"\nmodule = "{long}.py"\n')
    with pytest.raises(ScenarioError) as info:
        load_scenario(path)
    assert one_line(info.value).startswith(f"{path}: controller.module: the path 'aaa")
    assert "cannot be resolved" in str(info.value) and len(str(info.value)) < 400
