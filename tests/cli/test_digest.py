"""The terminal gets plain lines after `reproduce` and `sweep`; the Markdown stays in the files."""
from __future__ import annotations

import json
from pathlib import Path

from auvtrack.cli.digest import reproduce_lines, sweep_lines

ROOT = Path(__file__).resolve().parents[2]


def _markdown(lines: list[str]) -> list[str]:
    """Lines with Markdown structure: headings, table rows, code spans, emphasis, links."""
    return [ln for ln in lines if ln.lstrip().startswith(("#", "|")) or any(m in ln for m in ("`", "**", "](", "---"))]


def test_reproduce_lines_are_each_status_and_verdict_in_plain_text():
    metrics = json.loads((ROOT / "docs" / "results" / "reproduce.json").read_text())
    lines = reproduce_lines(metrics)
    assert not _markdown(lines), lines
    assert lines[0] == "status: " + ", ".join(f"{k} {v}" for k, v in metrics["status"].items())
    for v in metrics["verdicts"]:
        assert f"{v['claim']}: {v['verdict']}" in lines
    assert len(lines) == 1 + len(metrics["verdicts"]) + len(metrics["forms"])
    for form, line in zip(metrics["forms"], lines[-len(metrics["forms"]):]):
        assert line.strip() == f"{form['label']}: " + " / ".join(v["verdict"] for v in form["verdicts"])


def test_sweep_lines_give_the_totals_and_one_line_per_group():
    group = {"samples": 4, "counts": {"failed": 1, "ok": 3}, "failure_rate": 0.25, "invalid_rate": 0.0}
    summary = {"study": "s", "samples": 8, "counts": {"ok": 7, "failed": 1}, "failure_rate": 0.125,
               "invalid_rate": 0.0, "groups": [{"key": {"controller.kind": k}, **group} for k in ("pid", "sta")]}
    lines = sweep_lines(summary)
    assert lines[0] == "sweep s: 8 samples, failed: 1, ok: 7; failure rate 12.50%."
    assert lines[1:] == [f"  controller.kind = {k}: 4 samples, failed: 1, ok: 3; failure rate 25.00%."
                         for k in ("pid", "sta")]
    assert not _markdown(lines), lines


def test_a_run_that_saturated_says_so_beside_status_ok(tmp_path, capsys):
    """PID against a 200 N surge limit: ok, with the saturation time the metrics measured."""
    import auvtrack
    from auvtrack.cli import main
    from auvtrack.cli.digest import saturation_warning

    args = ["sim.duration=10", "controller.kind=pid", "actuator.tau_max=[200, 100, 100]"]
    res = auvtrack.simulate("paper", args, warn=False)
    assert res.ok and res.metrics["t_sat_tau_u"] > 0
    line = saturation_warning(res.metrics, 10.0)
    assert line.startswith(f"status ok, but the inputs saturated: surge {res.metrics['t_sat_tau_u']:.3g} s of 10 s;")
    assert line.endswith(f"largest position error {res.metrics['max_abs_x']:.3g} m (x)")
    assert main(["run", "paper", "--out", str(tmp_path / "r"), *(a for s in args for a in ("--set", s))]) == 0
    assert f"warning: {line}" in capsys.readouterr().err
    unsaturated = auvtrack.simulate("paper", ["sim.duration=1", "controller.kind=pid"], warn=False).metrics
    assert saturation_warning(unsaturated, 1.0) is None
