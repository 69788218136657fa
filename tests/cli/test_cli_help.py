"""What a newcomer reads first: ``auvtrack --help`` and where ``auvtrack run`` writes."""
from __future__ import annotations

import inspect
from pathlib import Path

from auvtrack.cli import EXIT_BAD_INPUT, EXIT_SIM_FAILED, cli, main
from auvtrack.simulation.run_folder import default_run_folder

PAPER = str(Path(__file__).resolve().parents[2] / "scenarios" / "paper.toml")


def test_top_level_help_shows_every_command_in_full_and_the_exit_codes(capsys):
    assert main(["--help"]) == 0
    out = capsys.readouterr().out
    flat = " ".join(out.split())
    for name, cmd in cli.commands.items():
        first = " ".join(inspect.cleandoc(cmd.help).split("\n\n")[0].split())
        assert f"{name} {first}" in flat, name  # the whole first paragraph, never cut with "..."
    assert "..." not in out.split("Commands:")[1]
    assert "Exit status:" in out
    for code in ("0", str(EXIT_BAD_INPUT), str(EXIT_SIM_FAILED), "130"):
        assert f"\n  {code} " in out
    assert "auvtrack warmup" in flat and "reproduce" in out.split("Commands:")[1].split()[0]


def test_default_run_folders_never_overwrite(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    args = ["run", PAPER, "--set", "sim.duration=0.05"]
    assert main(args) == 0 and main(args) == 0 and main([*args, "--set", "controller.kind=ftsmc"]) == 0
    out = capsys.readouterr().out
    made = sorted(p.name for p in (tmp_path / "runs").iterdir())
    assert made == sorted(["paper-fxtntsmc", "paper-fxtntsmc-2", "paper-ftsmc"])
    assert "written: runs/paper-fxtntsmc-2" in out
    assert default_run_folder("a b/c", "k", tmp_path) == tmp_path / "a_b_c-k"
    # an explicit --out is used as given
    assert main([*args, "--out", str(tmp_path / "mine")]) == 0 and main([*args, "--out", str(tmp_path / "mine")]) == 0
    assert not (tmp_path / "mine-2").exists()
