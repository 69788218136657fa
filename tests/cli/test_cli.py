"""The command line as a user meets it: outputs, exit codes, one-line errors, no tracebacks."""
import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from scipy.io import loadmat

from auvtrack.cli import EXIT_BAD_INPUT, EXIT_SIM_FAILED, main

ROOT = Path(__file__).resolve().parents[2]
PAPER = ROOT / "scenarios" / "paper.toml"
REQUIRED = ["t", "x", "y", "z", "theta", "psi", "u", "v", "w", "q", "r", "tau_u", "tau_q", "tau_r",
            "xd", "yd", "zd", "ex", "ey", "ez", "rho_x", "rho_y", "rho_z", "chi_x", "chi_y", "chi_z",
            "chi_hat_x", "chi_hat_y", "chi_hat_z"]


def test_run_writes_the_run_folder_contract(tmp_path, capsys):
    out = tmp_path / "fxt"
    assert main(["run", str(PAPER), "--out", str(out), "--mat", "--set", "sim.duration=2"]) == 0
    df = pd.read_csv(out / "trajectory.csv")
    assert all(c in df.columns for c in REQUIRED)
    assert len(df) == 201 and df["t"].iloc[-1] == pytest.approx(2.0)
    run = json.loads((out / "run.json").read_text())
    assert run["status"] == "ok" and run["failure"] is None
    sc = run["scenario"]
    for key in ("vehicle", "uncertainty", "disturbance", "reference", "initial", "controller", "sim", "seed"):
        assert key in sc, key
    assert sc["sim"]["dt"] == 0.001 and sc["controller"]["kind"] == "fxtntsmc"
    assert "rmse_x" in run["metrics"] and "tv_tau_u" in run["metrics"]
    mat = loadmat(out / "trajectory.mat")
    np.testing.assert_allclose(mat["ex"].ravel(), df["ex"].to_numpy(), rtol=1e-12, atol=0)
    err = capsys.readouterr().err
    assert "widened" in err  # the Section 4 start treatment is announced, never silent


def test_failed_run_exits_3_keeps_the_partial_result_and_says_why(tmp_path, capsys):
    out = tmp_path / "tip"
    code = main(["run", str(PAPER), "--out", str(out), "--set", "controller.kind=open_loop",
                 "--set", "controller.tau0=[0, 200, 0]", "--set", "sim.duration=30"])
    assert code == EXIT_SIM_FAILED
    err = capsys.readouterr().err.strip().splitlines()
    assert any(line.startswith("auvtrack: simulation failed at t = ") and "pitch" in line for line in err)
    run = json.loads((out / "run.json").read_text())
    assert run["status"] == "failed" and run["failure"]["cause"] == "pitch_limit"
    df = pd.read_csv(out / "trajectory.csv")
    assert 0 < len(df) < 3001 and df["t"].iloc[-1] <= run["failure"]["time"]


@pytest.mark.parametrize("args, field", [
    (["run", "no/such/file.toml"], "no/such/file.toml"),
    (["run", str(PAPER), "--set", "vehicle.l=0"], "vehicle.l"),
    (["check", str(PAPER), "--set", "sim.dt=0"], "sim.dt"),
    (["bounds", str(PAPER), "--set", "controller.kind=ftsmc"], "controller.kind"),
    (["bench", "--repeat", "0"], "--repeat: must be in [1, 1000]"),
    (["bench", "--duration", "-1"], "--duration: must be a finite number > 0"),
    (["run", str(PAPER), "--bogus"], "No such option '--bogus'"),  # usage errors are one line too
    (["reproduce", "--out", str(PAPER)], "is a file"),
    (["check", str(PAPER), "--set", "sim.duration=1e7"], "sim.duration: sim.duration / sim.dt"),
    (["check", str(PAPER), "--set", "reference.kind=waypoints", "--set", 'reference.points=[[0,0,0],[1,"2",0]]'],
     "reference.points.1.1: must be a number (got '2')"),
])
def test_bad_input_is_one_line_with_status_2(args, field, capsys):
    assert main(args) == EXIT_BAD_INPUT
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and err.startswith("auvtrack: error:") and field in err
    assert "Traceback" not in err


def test_console_script_has_no_traceback_and_status_2():
    p = subprocess.run([sys.executable, "-m", "auvtrack.cli", "run", str(PAPER), "--set", "sim.duration=-1"],
                       capture_output=True, text=True, cwd=ROOT)
    assert p.returncode == EXIT_BAD_INPUT
    assert p.stderr.count("\n") == 1 and "sim.duration" in p.stderr and "Traceback" not in p.stderr


def test_bounds_says_the_section4_guarantee_is_vacuous(capsys):
    assert main(["bounds", str(PAPER)]) == 0
    text = capsys.readouterr().out
    assert "VACUOUS" in text and "T1  >=" in text
    assert main(["bounds", str(PAPER), "--json"]) == 0
    b = json.loads(capsys.readouterr().out)
    assert b["T1"] > 283 and b["T1_is_lower_bound"] is True


def test_reproduce_quick_writes_figures_tables_and_verdicts(tmp_path):
    from auvtrack.studies.reproduce import reproduce

    summary = reproduce(tmp_path, quick=True)
    for name in ("fig3_trajectory3d", "fig4_positions", "fig5_velocities", "fig6_inputs", "fig7_errors", "fig8_chi"):
        assert (tmp_path / "figures" / f"{name}.png").stat().st_size > 10_000
        assert (tmp_path / "figures" / f"{name}.pdf").exists()
    from report_check import check_html_report

    html = check_html_report(tmp_path, "summary.md")  # every figure embedded, the same report as summary.md
    from auvtrack.studies.reproduce import FORMS

    # 3 claims x (paper gains, tuned gains, each form of the law)
    assert html.count('class="verdict ') == 3 * (2 + len(FORMS)) and "virtual point" in html
    assert summary in (tmp_path / "summary.md").read_text()
    table = (tmp_path / "summary.md").read_text()
    assert "| metric (docs/metrics.md) | unit | window |" in table
    assert "| rmse_x | m | whole run |" in table and "| t_sat_tau_u | s | whole run |" in table
    m = json.loads((tmp_path / "metrics.json").read_text())
    assert m["status"] == {"FXTNTSMC": "ok", "FTSMC": "ok"}
    assert {v["verdict"] for v in m["verdicts"]} <= {"supported", "not supported", "mixed"}
    assert len(m["verdicts"]) == 3 and "faster convergence" in summary
    # every verdict states its conditions, and the paper's printed forms are judged too
    assert m["conditions"]["estimator"].startswith("effective") and "xi0" in m["conditions"]["start"]
    assert all(v["conditions"] for v in m["verdicts"]) and "Conditions of the FXTNTSMC" in summary
    forms = {f["name"]: f for f in m["forms"]}
    assert {"corrected", "printed_law34", "printed_surface28", "printed_baseline24", "printed_start"} <= set(forms)
    assert forms["corrected"]["full_window"] == m["full_window"]["FXTNTSMC"]
    assert forms["printed_law34"]["conditions"]["estimator"].startswith("law (34)")
    assert forms["printed_start"]["status"] == "refused"
    assert {v["verdict"] for v in forms["printed_start"]["verdicts"]} == {"not testable"}
    assert forms["printed_baseline24"]["status"] == "failed"
    assert {v["verdict"] for v in forms["printed_baseline24"]["verdicts"]} == {"not testable"}
    for kind in ("fxtntsmc", "ftsmc"):
        assert (tmp_path / kind / "trajectory.csv").exists() and (tmp_path / kind / "run.json").exists()
    # the fair-tuning comparison really runs the tuned gains (a preset next to written-out gains would not)
    assert len(m["tuned"]["verdicts"]) == 3 and "under fair tuning" in summary
    from auvtrack.control.gain_presets import get_gain_preset

    for kind in ("fxtntsmc", "ftsmc"):
        ctrl = json.loads((tmp_path / "tuned" / kind / "run.json").read_text())["scenario"]["controller"]
        for k, v in get_gain_preset(f"{kind}_tuned").gains.items():
            assert ctrl[k] == v, (kind, k)


def test_subcommand_help_lists_the_exit_codes(capsys):
    """The top-level --help has its own table (tests/cli/test_cli_help.py); run, check and sweep repeat it."""
    from auvtrack.cli import EXIT_CODES

    for args in (["run", "--help"], ["check", "--help"], ["sweep", "--help"]):
        assert main(args) == 0
        text = " ".join(capsys.readouterr().out.split())
        for code, meaning in EXIT_CODES:
            assert f"{code} {' '.join(meaning.split())}" in text, (args, code)
        assert "130 interrupted (Ctrl-C or SIGTERM, any command): a run keeps its partial result" \
            in text
