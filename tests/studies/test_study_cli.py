"""``auvtrack study``: listing, dispatch, one-line errors; the shared report helpers."""
from __future__ import annotations

import json
import math
from pathlib import Path

import pytest

from auvtrack.cli import main
from auvtrack.studies import registry
from auvtrack.report import Report, failure_cause, fmt, metrics_table, write_json


def test_unknown_study_is_one_line_exit_2(capsys):
    assert main(["study", "no-such-study"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1
    assert err.startswith("auvtrack: error: unknown study 'no-such-study'")
    assert "ablation" in err and "fixed-time" in err


def test_study_list_and_help_show_every_study_with_its_summary(capsys):
    studies = registry.all_studies()
    assert {"ablation", "fixed-time"} <= set(studies)
    assert main(["study", "list"]) == 0
    out = capsys.readouterr().out
    for name in ("ablation", "fixed-time"):
        assert f"{name}: {studies[name].summary}" in out
    assert main(["study", "--help"]) == 0
    help_text = capsys.readouterr().out
    assert "Studies:" in help_text and "ablation" in help_text and "fixed-time" in help_text


def test_study_dispatches_with_default_out_and_quick(monkeypatch, tmp_path, capsys):
    calls = []

    def fake_run(out: Path, *, quick: bool = False, progress: bool = False) -> Path:
        calls.append((Path(out), quick, progress))
        return Path(out) / "report.md"

    spec = registry.StudySpec("fake", fake_run, "a fake study")
    monkeypatch.setattr(registry, "get_study", lambda name: spec if name == "fake" else registry.get_study(name))
    monkeypatch.chdir(tmp_path)
    assert main(["study", "fake", "--quick"]) == 0
    assert calls[-1] == (Path("studies") / "fake", True, True)
    assert main(["study", "fake", "--out", str(tmp_path / "x")]) == 0
    assert calls[-1] == (tmp_path / "x", False, True)
    assert "report:" in capsys.readouterr().out


def test_write_json_turns_nonfinite_into_null(tmp_path):
    import numpy as np

    p = write_json(tmp_path / "sub" / "r.json", {"a": math.inf, "b": [math.nan, 1.5, np.float64(-math.inf)],
                                                 "c": np.arange(2), "d": (1, "x")})
    text = p.read_text()
    assert "Infinity" not in text and "NaN" not in text
    assert json.loads(text) == {"a": None, "b": [None, 1.5, None], "c": [0, 1], "d": [1, "x"]}


def test_fmt_and_metrics_table():
    assert fmt(None) == "–" and fmt(math.nan) == "–" and fmt(math.inf) == "inf" and fmt(-math.inf) == "-inf"
    assert fmt(1.234567) == "1.235" and fmt(3) == "3" and fmt(True) == "yes" and fmt("a|b") == "a\\|b"
    t = metrics_table({"A": {"rmse": 0.5, "tv": math.inf}, "B": {"rmse": 2.0}}, ["rmse", "tv"], label="cfg")
    lines = t.splitlines()
    assert lines[0] == "| cfg | rmse | tv |"
    assert lines[2] == "| A | 0.5 | inf |" and lines[3] == "| B | 2 | – |"


def test_report_writes_markdown_with_linked_png(tmp_path):
    from matplotlib.figure import Figure

    rep = Report(tmp_path / "rep", "Title")
    rep.heading("Section")
    rep.paragraph("Some text.")
    rep.bullets(["one", "two"])
    rep.table(["a", "b"], [[1, 2.5]])
    fig = Figure()
    fig.subplots().plot([0, 1], [1, 0])
    png = rep.figure(fig, "fig1", "caption")
    path = rep.write()
    text = path.read_text()
    assert path == tmp_path / "rep" / "report.md"
    assert text.startswith("# Title\n") and "## Section" in text and "- one" in text and "| 1 | 2.5 |" in text
    assert "![caption](figures/fig1.png)" in text
    assert png.exists() and png.read_bytes()[:4] == b"\x89PNG"
    with pytest.raises(ValueError):
        rep.table(["a", "b"], [[1]])


class _R:
    def __init__(self, failure):
        self.failure = failure


@pytest.mark.parametrize("failure, cause", [
    (None, None),
    ({"cause": "pitch_limit", "detail": "pitch limit exceeded"}, "pitch_limit"),
    ({"cause": "nonfinite", "detail": "non-finite state"}, "nonfinite"),
    ({"cause": "controller", "detail": "envelope violated: |e_i| >= rho_i"}, "envelope_violation"),
    ({"cause": "controller", "detail": "controller produced a non-finite input"}, "nonfinite_input"),
    ({"cause": "controller", "detail": "start on or outside the envelope and widen_start is off"}, "start_refused"),
])
def test_failure_cause_classification(failure, cause):
    assert failure_cause(_R(failure)) == cause


def test_metric_units_name_each_axis_and_input():
    from auvtrack.metrics import METRIC_NAMES
    from auvtrack.report import metric_unit

    assert metric_unit("rmse_x") == "m" and metric_unit("settle_5cm_y") == "s" and metric_unit("itae_z") == "m*s^2"
    assert metric_unit("max_abs_tau_u") == "N" and metric_unit("max_abs_tau_q") == "N*m"
    assert metric_unit("energy_tau_r") == "N^2*m^2*s" and metric_unit("tv_tau_u") == "N/s"
    assert all(metric_unit(n) for n in METRIC_NAMES)  # every metric has a unit
