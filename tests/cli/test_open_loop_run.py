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
