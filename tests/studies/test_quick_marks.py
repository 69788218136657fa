"""A ``--quick`` study run is marked as such: its report opens with the quick banner and its
results.json says ``"quick": true``; a full run carries neither."""
from __future__ import annotations

import json

from auvtrack.report import QUICK_BANNER, Report, write_json
from auvtrack.studies.registry import StudySpec, run_study


def _tiny_study(out, *, quick=False, progress=False):
    write_json(out / "results.json", {"rows": [1, 2], "quick": quick})
    rep = Report(out, "Tiny")
    rep.paragraph("body")
    return rep.write(html=None)


def test_a_quick_run_is_marked_and_a_full_run_is_not(tmp_path):
    spec = StudySpec("tiny", _tiny_study)
    quick = run_study(spec, tmp_path / "q", quick=True)
    text = quick.read_text()
    assert text.index(QUICK_BANNER) < text.index("body")
    assert json.loads((tmp_path / "q" / "results.json").read_text()) == {"quick": True, "rows": [1, 2]}
    full = run_study(spec, tmp_path / "f", quick=False)
    assert QUICK_BANNER not in full.read_text()
    assert json.loads((tmp_path / "f" / "results.json").read_text()) == {"rows": [1, 2], "quick": False}
    Report(tmp_path / "after", "after").paragraph("x")  # the mark ends with the run
    assert not any(QUICK_BANNER in b.data.get("text", "") for b in Report(tmp_path, "t").blocks)
