"""Run folders: always one run's complete output (concurrent writers, failures, symlinks), checked
before the run, and reproducing themselves from their scenario.toml byte for byte."""
from __future__ import annotations

import contextlib
import io
import json
import os
import subprocess
import sys
import threading
from pathlib import Path
from unittest import mock

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from auvtrack._atomic import atomic_write, open_exclusive
from auvtrack.cli import EXIT_BAD_INPUT, EXIT_SIM_FAILED, main
from auvtrack.control import BUILTIN_NAMES
from auvtrack.simulation.result import RUN_FILES, Result, verify_run_folder

ROOT = Path(__file__).resolve().parents[2]
PAPER = ROOT / "scenarios" / "paper.toml"


def _quiet_main(args):
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()) as err:
        code = main(args)
    return code, err.getvalue()


def _assert_one_complete_run(folder: Path, expected: dict[float, bytes]) -> None:
    """``folder`` is exactly one of the runs: its files agree with each other and with that run."""
    assert sorted(os.listdir(folder)) == ["run.json", "scenario.toml", "trajectory.csv"]
    assert verify_run_folder(folder) == []
    doc = json.loads((folder / "run.json").read_text())
    duration = doc["scenario"]["sim"]["duration"]
    assert (folder / "trajectory.csv").read_bytes() == expected[duration]
    assert f"duration = {duration!r}" in (folder / "scenario.toml").read_text()
    assert [e for e in os.listdir(folder.parent) if e != folder.name] == []  # no temporary left


def _expected_csv(tmp: Path, durations) -> dict[float, bytes]:
    out = {}
    for d in durations:
        assert main(["run", str(PAPER), "--out", str(tmp / f"ref-{d}"), "--set", f"sim.duration={d}"]) == 0
        out[d] = (tmp / f"ref-{d}" / "trajectory.csv").read_bytes()
    return out


DURATIONS = (0.03, 0.04, 0.05, 0.06)


@pytest.fixture(scope="module")
def expected(tmp_path_factory):
    with contextlib.redirect_stderr(io.StringIO()), contextlib.redirect_stdout(io.StringIO()):
        return _expected_csv(tmp_path_factory.mktemp("ref"), DURATIONS)


@settings(max_examples=6, deadline=None)
@given(runs=st.lists(st.sampled_from(DURATIONS), min_size=2, max_size=4), again=st.booleans())
def test_concurrent_runs_into_one_folder_leave_one_complete_run(expected, runs, again):
    """Threads running ``auvtrack run --out SAME`` at once (the kernel releases the GIL, so the
    simulations and the saves really overlap): every run succeeds and the folder is one of them."""
    import tempfile

    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp) / "parent" / "same"
        rounds = 2 if again else 1  # the second round replaces an existing run folder
        for _ in range(rounds):
            codes: list = []
            barrier = threading.Barrier(len(runs))

            def one(d):
                barrier.wait()
                codes.append(_quiet_main(["run", str(PAPER), "--out", str(folder), "--set", f"sim.duration={d}"])[0])

            threads = [threading.Thread(target=one, args=(d,)) for d in runs]
            for t in threads:
                t.start()
            for t in threads:
                t.join()
            assert codes == [0] * len(runs)
            _assert_one_complete_run(folder, expected)


def test_concurrent_processes_into_one_folder(tmp_path, expected):
    """The reported case: separate ``auvtrack run`` processes with the same --out."""
    folder = tmp_path / "runs" / "same"
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    procs = [subprocess.Popen([sys.executable, "-m", "auvtrack.cli", "run", str(PAPER), "--out", str(folder),
                               "--set", f"sim.duration={d}"], env=env, cwd=tmp_path,
                              stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True) for d in DURATIONS[:3]]
    for p in procs:
        _, err = p.communicate(timeout=600)
        assert p.returncode == 0, err
    _assert_one_complete_run(folder, expected)


def test_a_failed_save_leaves_the_previous_run_whole(tmp_path, expected):
    folder = tmp_path / "run"
    assert _quiet_main(["run", str(PAPER), "--out", str(folder), "--set", "sim.duration=0.03"])[0] == 0
    before = {n: (folder / n).read_bytes() for n in os.listdir(folder)}
    with mock.patch.object(Result, "_save_mat", side_effect=OSError(28, "No space left on device")):
        code, err = _quiet_main(["run", str(PAPER), "--out", str(folder), "--mat", "--set", "sim.duration=0.05"])
    assert code == EXIT_SIM_FAILED and "No space left" in err
    assert {n: (folder / n).read_bytes() for n in os.listdir(folder)} == before
    assert os.listdir(tmp_path) == ["run"]  # the half-written temporary folder is gone


# ---------------------------------------------------------------- symlinks and bad --out

def test_open_exclusive_never_follows_a_planted_symlink(tmp_path):
    victim = tmp_path / "victim.txt"
    victim.write_text("precious")
    (tmp_path / "link").symlink_to(victim)
    with pytest.raises(FileExistsError):
        open_exclusive(tmp_path / "link")
    (tmp_path / "dangling").symlink_to(tmp_path / "nowhere")
    with pytest.raises(FileExistsError):
        open_exclusive(tmp_path / "dangling")
    assert not (tmp_path / "nowhere").exists()
    atomic_write(tmp_path / "link", "new")  # replaces the link itself, never writes through it
    assert victim.read_text() == "precious" and not (tmp_path / "link").is_symlink()
    assert (tmp_path / "link").read_text() == "new"


def test_symlinks_at_the_old_temporary_names_are_harmless(tmp_path):
    """The old writer used ``trajectory.csv.tmp``: a symlink there overwrote its target."""
    victim = tmp_path / "victim.txt"
    victim.write_text("precious")
    folder = tmp_path / "run"
    assert _quiet_main(["run", str(PAPER), "--out", str(folder), "--set", "sim.duration=0.03"])[0] == 0
    for name in ("trajectory.csv.tmp", "run.json.tmp"):
        (folder / name).symlink_to(victim)
    code, err = _quiet_main(["run", str(PAPER), "--out", str(folder), "--set", "sim.duration=0.03"])
    assert code == EXIT_BAD_INPUT and "holds 2 entries that a run folder does not" in err
    assert victim.read_text() == "precious"


def test_out_as_a_symlink_is_refused_and_its_target_untouched(tmp_path):
    target = tmp_path / "elsewhere"
    target.mkdir()
    (tmp_path / "out").symlink_to(target)
    code, err = _quiet_main(["run", str(PAPER), "--out", str(tmp_path / "out"), "--set", "sim.duration=0.03"])
    assert code == EXIT_BAD_INPUT and "is a symbolic link" in err
    assert os.listdir(target) == []


class _Ran(Exception):
    pass


def _a_file(p: Path) -> Path:
    p.write_text("x")
    return p


def _a_folder_of_mine(p: Path) -> Path:
    p.mkdir()
    (p / "notes.txt").write_text("mine")
    return p


def _below_a_file(p: Path) -> Path:
    return _a_file(p) / "sub"


@pytest.mark.parametrize("make, text", [
    (_a_file, "is a file, not a folder"),
    (_a_folder_of_mine, "holds 1 entry that a run folder does not"),
    (_below_a_file, "cannot write there"),
    (lambda p: p.parent / ("n" * 300), "is longer than"),
    (lambda p: Path(str(p) + "\x00x"), "NUL character"),
    (lambda p: p.parent / "empty" / "..", "must name a folder of its own"),
    (lambda p: Path("/"), "must name a folder of its own"),
], ids=["file", "foreign-folder", "below-a-file", "too-long", "nul", "dot-dot", "root"])
def test_a_bad_out_is_refused_before_the_simulation(tmp_path, make, text):
    out = make(tmp_path / "out")
    with mock.patch("auvtrack.simulation.pipeline.run_prepared", side_effect=_Ran):
        code, err = _quiet_main(["run", str(PAPER), "--out", str(out), "--set", "sim.duration=0.03"])
    assert code == EXIT_BAD_INPUT, err
    assert len(err.strip().splitlines()) == 1 and err.startswith("auvtrack: error: --out: ") and text in err
    if (tmp_path / "out" / "notes.txt").exists():
        assert (tmp_path / "out" / "notes.txt").read_text() == "mine"


# ---------------------------------------------------------------- scenario.toml reproduces the run

VARIANTS = {
    "continuous": [],
    "sampled": ["sim.control_rate=100"],
    "noise": ["sim.control_rate=200", "sensor.sigma_eta=[0.01, 0.01, 0.01, 0.001, 0.001]",
              "sensor.sigma_nu=[0.01, 0.01, 0.01, 0.001, 0.001]"],
    "currents": ["disturbance.1.kind=current", "disturbance.1.sample_dt=0.01", "disturbance.2.kind=current",
                 "disturbance.2.sigma=[0.2, 0.1, 0.05]", "disturbance.2.tau=5"],
}
CASES = [(kind, v) for kind in sorted(BUILTIN_NAMES) for v in VARIANTS]


@pytest.mark.parametrize("kind, variant", CASES, ids=[f"{k}-{v}" for k, v in CASES])
def test_scenario_toml_reproduces_the_trajectory_byte_for_byte(tmp_path, kind, variant):
    first, second = tmp_path / "first", tmp_path / "second"
    args = ["--set", f"controller.kind={kind}", "--set", "sim.duration=0.5", "--set", "seed=7"]
    if kind == "open_loop_actuators":  # drives a 6-DOF plant's fins and propeller (issue 11)
        args += ["--set", "plant.model=6dof"]
    for ov in VARIANTS[variant]:
        args += ["--set", ov]
    code, err = _quiet_main(["run", str(PAPER), "--out", str(first), *args])
    assert code in (0, 3), err  # a failed run reproduces its partial trajectory too
    assert sorted(os.listdir(first)) == sorted(n for n in RUN_FILES if n != "trajectory.mat")
    code2, err2 = _quiet_main(["run", str(first / "scenario.toml"), "--out", str(second)])
    assert code2 == code, err2
    assert (second / "trajectory.csv").read_bytes() == (first / "trajectory.csv").read_bytes()
    assert (second / "scenario.toml").read_bytes() == (first / "scenario.toml").read_bytes()
    a, b = (json.loads((f / "run.json").read_text()) for f in (first, second))
    assert a["metrics"] == b["metrics"] and a["scenario"] == b["scenario"] and a["failure"] == b["failure"]


def test_concurrent_runs_without_out_each_get_their_own_folder(tmp_path, monkeypatch, expected):
    """The default folders (runs/<name>-<controller>, -2, -3...) are taken when a run is
    published, so runs started together never overwrite one another."""
    monkeypatch.chdir(tmp_path)
    barrier = threading.Barrier(len(DURATIONS))
    codes: list = []

    def one(d):
        barrier.wait()
        codes.append(_quiet_main(["run", str(PAPER), "--set", f"sim.duration={d}"])[0])

    threads = [threading.Thread(target=one, args=(d,)) for d in DURATIONS]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert codes == [0] * len(DURATIONS)
    folders = sorted(os.listdir(tmp_path / "runs"))
    assert folders == sorted(["paper-fxtntsmc"] + [f"paper-fxtntsmc-{n}" for n in range(2, len(DURATIONS) + 1)])
    seen = set()
    for name in folders:
        folder = tmp_path / "runs" / name
        assert verify_run_folder(folder) == []
        duration = json.loads((folder / "run.json").read_text())["scenario"]["sim"]["duration"]
        assert (folder / "trajectory.csv").read_bytes() == expected[duration]
        seen.add(duration)
    assert seen == set(DURATIONS)


def test_a_folder_moved_aside_while_it_is_checked_counts_as_absent(tmp_path):
    """Concurrent writers rename run folders in and out: a folder that vanishes between the look
    at the path and the listing is absent (not "cannot be read"), so a concurrent run is not refused."""
    from auvtrack.simulation.result import run_folder_problem

    folder = tmp_path / "run"
    folder.mkdir()
    with mock.patch("auvtrack.simulation.result.os.listdir", side_effect=FileNotFoundError(2, "gone")):
        assert run_folder_problem(folder) is None
    with mock.patch("auvtrack.simulation.result.os.listdir", side_effect=PermissionError(13, "denied")):
        assert "cannot be read" in run_folder_problem(folder)


def test_publish_looks_again_when_the_folder_is_replaced_during_its_check(tmp_path):
    """A reason found while another writer swapped the folder is not trusted: publish retries and
    succeeds; a reason about the same, unchanged folder is final."""
    from auvtrack._atomic import FolderError, make_temp_folder, publish_folder

    final = tmp_path / "run"
    final.mkdir()
    (final / "run.json").write_text("{}")
    calls = []

    def racing(path):  # the first check sees a folder that another writer then moves aside
        calls.append(path)
        if len(calls) == 1:
            os.rename(path, tmp_path / "moved")
            return "cannot be read (No such file or directory)"
        return None

    tmp = make_temp_folder(final)
    (tmp / "run.json").write_text('{"new": 1}')
    publish_folder(tmp, final, racing)
    assert json.loads((final / "run.json").read_text()) == {"new": 1}

    tmp2 = make_temp_folder(final)
    with pytest.raises(FolderError, match="not replaceable"):
        publish_folder(tmp2, final, lambda p: "not replaceable")
    assert tmp2.exists() and json.loads((final / "run.json").read_text()) == {"new": 1}
