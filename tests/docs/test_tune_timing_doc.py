"""docs/tuning.md quotes the cost of ``auvtrack tune`` from the stored records of benchmarks/tune_timing.py."""
from __future__ import annotations

import importlib.util
import json
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
RECORDS = ("tune_timing.json", "tune_timing_before.json", "tune_timing_1worker.json")


def _script():
    spec = importlib.util.spec_from_file_location("tune_timing", ROOT / "benchmarks" / "tune_timing.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.mark.parametrize("name", RECORDS)
def test_the_tuning_doc_quotes_each_stored_record(name):
    record = json.loads((ROOT / "benchmarks" / name).read_text())
    assert record["suite"] == "auv-track-v2" and record["split"] == "training"
    assert record["median"]["trials_per_s"] > 0 and record["repeats"]
    assert _script().summary(record) in " ".join((ROOT / "docs" / "tuning.md").read_text().split())


def test_the_records_measure_the_same_trials():
    """Before and after fly the same study (same sampler seed and budget): the same trials, runs and steps."""
    records = [json.loads((ROOT / "benchmarks" / n).read_text()) for n in RECORDS]
    keys = ("trials", "complete", "pruned", "refused", "runs", "steps", "best_score")
    assert len({(r["budget"], r["controller"], r["suite"]) for r in records}) == 1
    assert {tuple(rep[k] for k in keys) for r in records for rep in r["repeats"]} == \
        {tuple(records[0]["repeats"][0][k] for k in keys)}
