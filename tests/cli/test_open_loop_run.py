"""``auvtrack run`` of the packaged turning circle: the summary names the manoeuvre (advance,
transfer, tactical diameter) and run.json keeps it; no tracking warnings (start off the reference,
saturated inputs) for an open-loop run."""
from __future__ import annotations

import json

from auvtrack.cli import main


def test_the_turning_circle_reports_its_manoeuvre_not_tracking(tmp_path, capsys):
    out = tmp_path / "tc"
    assert main(["run", "remus100_turning_circle", "--set", "sim.duration=60", "--out", str(out)]) == 0
    cap = capsys.readouterr()
    assert "turning circle (starboard): advance " in cap.out and "tactical diameter" in cap.out
    assert "warning" not in cap.err and "note: start:" not in cap.err
    meta = json.loads((out / "run.json").read_text())["meta"]
    m = meta["manoeuvre"]
    assert m["manoeuvre"] == "turning_circle" and 5.0 < m["advance_m"] < 60.0 and m["tactical_diameter_m"] > m["transfer_m"]
    summary = cap.out.splitlines()[0]
    assert summary.startswith("Result(status='ok'") and "rmse" not in summary and "turning circle" in summary


def test_simulate_of_an_open_loop_run_carries_its_manoeuvre_and_no_tracking_error():
    """The API's result holds the same figures as the CLI's (meta["manoeuvre"]) and its repr prints them,
    not a tracking RMSE; a tracking run's repr keeps its RMSE."""
    import auvtrack

    res = auvtrack.simulate("remus100_turning_circle", ["sim.duration=60"])
    assert not res.tracks and res.meta["manoeuvre"]["manoeuvre"] == "turning_circle"
    assert "rmse" not in repr(res) and "turning circle (starboard): advance " in repr(res)


def test_the_repr_of_an_open_loop_result_never_shows_a_tracking_error():
    """From the metadata alone: a manoeuvre's figures, 'no manoeuvre recognised' for an open-loop run
    that flew none (also one loaded from an older run.json without the key), the RMSE for a tracking run."""
    import numpy as np

    from auvtrack.channels import BASE_CHANNELS
    from auvtrack.simulation.result import Result

    ch = {name: np.zeros(3) for name in BASE_CHANNELS}
    ch["t"] = np.arange(3.0)
    metrics = {f"rmse_{a}": 99.0 for a in "xyz"}
    zigzag = {"manoeuvre": "zigzag", "zigzag_psi_deg": 20.0, "overshoot_1_deg": 5.0, "overshoot_2_deg": 7.0,
              "initial_turning_time_s": 9.0, "period_s": 30.0, "reversals": 3}
    flew = Result(ch, {"controller": {"kind": "open_loop_actuators"}}, "ok", None, metrics, {"manoeuvre": zigzag})
    assert "rmse" not in repr(flew) and "zig-zag (reversal at 20 deg): overshoots 5 deg, 7 deg" in repr(flew)
    none = Result(ch, {"controller": {"kind": "open_loop"}}, "ok", None, metrics, {"manoeuvre": None})
    older = Result(ch, {"controller": {"kind": "open_loop"}}, "ok", None, metrics, {})
    for res in (none, older):
        assert not res.tracks and "rmse" not in repr(res) and "open loop (no manoeuvre recognised)" in repr(res)
    tracking = Result(ch, {"controller": {"kind": "pid"}}, "ok", None, metrics, {})
    assert tracking.tracks and "rmse[m]=(x 99, y 99, z 99)" in repr(tracking)
