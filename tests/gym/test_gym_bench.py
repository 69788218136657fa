"""``auvtrack bench --gym``: the record's shape (speed is a benchmark's business, not a test's)."""
from __future__ import annotations

from auvtrack.perf.gym_bench import bench_gym


def test_bench_gym_reports_each_size_and_the_ratio():
    doc = bench_gym(sizes=(1, 3), repeat=1, steps=3, substeps=2)
    assert [r["num_envs"] for r in doc["rows"]] == [1, 3]
    for r in doc["rows"]:
        assert r["env_steps_per_s"] > 0
        assert r["ratio_to_batch"] > 0
    assert doc["batch"]["runs"] == 3 and doc["batch"]["statuses"] == ["ok"]
    assert doc["machine"]["load_avg_1_5_15"] is not None


def test_bench_gym_refuses_options_it_does_not_use(capsys):
    from auvtrack.cli import main

    assert main(["bench", "--gym", "--out", "x"]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "--out" in err
