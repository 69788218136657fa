"""Every command of ``auvtrack`` stops on SIGINT and SIGTERM alike: exit 130, one line, no traceback.

The handling is installed once, around every command (:func:`auvtrack.cli.main`); the test walks
the click group, so a command added later is covered without being named here.
"""
from __future__ import annotations

import signal
import sys

import click
import pytest

from auvtrack.cli import EXIT_INTERRUPTED, cli, main

pytestmark = pytest.mark.skipif(not sys.platform.startswith("linux"), reason="POSIX signals")

def _leaves(group: click.Group, path: tuple[str, ...] = ()) -> dict[tuple[str, ...], click.Command]:
    """Every command that runs something, by its path (a group's subcommands, e.g. ``scenarios list``)."""
    found: dict[tuple[str, ...], click.Command] = {}
    for name, cmd in group.commands.items():
        if isinstance(cmd, click.Group):
            found.update(_leaves(cmd, (*path, name)))
        else:
            found[(*path, name)] = cmd
    return found


COMMANDS = _leaves(cli)


def _required_args(cmd: click.Command) -> list[str]:
    """Placeholder values for the command's required arguments and options (the callback is replaced)."""
    args: list[str] = []
    for p in cmd.params:
        if p.required:
            args += ["1"] if isinstance(p, click.Argument) else [p.opts[0], "1"]
    return args


@pytest.fixture
def restore_signals():
    """A stopped command leaves both signals ignored (its process is ending): not this test process."""
    saved = {s: signal.getsignal(s) for s in (signal.SIGINT, signal.SIGTERM)}
    yield
    for s, handler in saved.items():
        signal.signal(s, handler)


def test_the_walk_finds_the_commands():
    names = {" ".join(path) for path in COMMANDS}
    assert {"run", "check", "reproduce", "study", "sweep", "compare", "tune", "train", "scenarios list"} <= names


@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGINT], ids=["SIGTERM", "SIGINT"])
@pytest.mark.parametrize("path", sorted(COMMANDS), ids=" ".join)
def test_a_signal_stops_every_command_with_one_line(path, sig, monkeypatch, capsys, restore_signals):
    cmd = COMMANDS[path]
    reached = []

    def signalled(**kwargs):
        reached.append(signal.getsignal(signal.SIGTERM))
        signal.raise_signal(sig)  # as a `kill` from outside while the command works
        reached.append("not stopped")

    monkeypatch.setattr(cmd, "callback", signalled)
    code = main([*path, *_required_args(cmd)])
    err = capsys.readouterr().err
    assert reached and reached[0] not in (signal.SIG_DFL, signal.SIG_IGN, None), reached  # a handler was in force
    assert reached[1:] == [], "the signal did not stop the command"
    assert code == EXIT_INTERRUPTED, err
    assert err.splitlines() == ["auvtrack: interrupted"], err
    assert signal.getsignal(signal.SIGTERM) == signal.SIG_IGN  # a second signal waits for the clean-up


@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGINT], ids=["SIGTERM", "SIGINT"])
def test_a_second_signal_while_a_command_cleans_up_is_ignored(sig, monkeypatch, capsys, restore_signals):
    cmd = cli.commands["check"]
    cleaned = []

    def signalled(**kwargs):
        try:
            signal.raise_signal(sig)
        finally:  # the command's clean-up, itself signalled again: it runs to its end
            signal.raise_signal(sig)
            cleaned.append(True)

    monkeypatch.setattr(cmd, "callback", signalled)
    assert main(["check", "1"]) == EXIT_INTERRUPTED
    assert cleaned == [True]
    assert capsys.readouterr().err.splitlines() == ["auvtrack: interrupted"]


def test_without_a_signal_the_handlers_are_restored(monkeypatch, restore_signals):
    before = {s: signal.getsignal(s) for s in (signal.SIGINT, signal.SIGTERM)}
    assert main(["scenarios", "list"]) == 0
    assert {s: signal.getsignal(s) for s in before} == before
