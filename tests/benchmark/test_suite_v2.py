"""auv-track-v2: its cells are feasible for both REMUS 100 truths, its splits disjoint, and a suite
whose reference a truth cannot fly is refused at load with the check that fails."""
from __future__ import annotations

from pathlib import Path

import pytest

from auvtrack.benchmark.suite import SPLITS, SuiteError, load_suite

ONE_CELL = """
name = "one-cell"
version = 1
seed = 5
seeds = 2
bootstrap_resamples = 200
feasibility = true
[base]
"vehicle.preset" = "remus100"
"sim.dt" = 0.002
"disturbance" = []
[tasks.turn]
duration = 20.0
reference = { kind = "circle", radius = RADIUS, omega = OMEGA, depth = 8.0 }
[tiers.prestero]
requires_plant = "6dof"
[tiers.prestero.set]
"plant.model" = "6dof"
"plant.preset" = "remus100_prestero"
"""


def _one_cell(tmp_path: Path, radius: float, feasibility: bool = True) -> Path:
    text = ONE_CELL.replace("RADIUS", repr(radius)).replace("OMEGA", repr(1.3 / radius))
    path = tmp_path / "one.toml"
    path.write_text(text if feasibility else text.replace("feasibility = true", "feasibility = false"))
    return path


@pytest.mark.slow
def test_the_shipped_v2_suite_loads_with_every_cell_feasible():
    """Loading runs the feasibility check on every (task, tier) cell at every cycled value and current corner."""
    suite = load_suite("auv-track-v2")
    assert suite.file.feasibility
    assert set(suite.tiers) == {"design", "digital", "truth_prestero", "truth_fossen", "field"}
    assert set(suite.tasks) == {"lawnmower", "waypoints", "helix", "depth"}


def test_v2_declares_disjoint_training_validation_and_evaluation_seeds():
    suite = load_suite("auv-track-v2", check=False)
    sets = {s: set(suite.split_seeds(s)) for s in SPLITS}
    assert all(sets.values())
    assert not sets["training"] & sets["evaluation"]
    assert not sets["validation"] & sets["evaluation"]
    assert not sets["training"] & sets["validation"]


def test_v2_field_tier_draws_both_truths_and_control_rates_in_10_to_50_hz():
    suite = load_suite("auv-track-v2", check=False)
    tier = suite.file.tiers["field"]
    assert set(tier.cycle["plant.preset"]) == {"remus100_prestero", "remus100_fossen"}
    assert all(10.0 <= r <= 50.0 for r in tier.cycle["sim.control_rate"])
    assert tier.set["disturbance"][0]["kind"] == "current"


def test_a_turn_tighter_than_the_truth_can_fly_is_refused_with_its_check(tmp_path):
    with pytest.raises(SuiteError) as info:
        load_suite(_one_cell(tmp_path, 3.0))
    msg = str(info.value)
    assert "\n" not in msg
    assert "task 'turn' under tier 'prestero' is infeasible" in msg and "turn to" in msg, msg


def test_the_same_cell_with_a_feasible_radius_loads(tmp_path):
    assert load_suite(_one_cell(tmp_path, 60.0)).tasks == ["turn"]


def test_without_the_flag_an_infeasible_cell_is_not_assessed(tmp_path):
    """v1 declares no feasibility check: its load (and fingerprint) stay as published."""
    assert load_suite(_one_cell(tmp_path, 3.0, feasibility=False)).tasks == ["turn"]


def test_the_feasibility_flag_is_not_part_of_the_fingerprint(tmp_path):
    (tmp_path / "a").mkdir()
    (tmp_path / "b").mkdir()
    a = load_suite(_one_cell(tmp_path / "a", 60.0), check=False).fingerprint()
    b = load_suite(_one_cell(tmp_path / "b", 60.0, feasibility=False), check=False).fingerprint()
    assert a != "" and a == b


def test_v2_run_score_puts_path_following_first_by_hand():
    """A completed run at the scales of xtrack, vtrack, along and rmse, no actuator use:
    (1 * 0.5 + 0.5 * 1 + 0.25 * 1 + 0.25 * 1) / (sum of the weights, 2.4) = 0.625."""
    suite = load_suite("auv-track-v2", check=False)
    zero = {c: 0.0 for c in suite.file.run_score.weights}
    run = zero | {"status": "ok", "t_stop": 120.0, "xtrack_rmse": 0.25, "vtrack_rmse": 0.5, "along_rmse": 2.0,
                  "rmse": 1.0}
    assert suite.run_score(run, "helix") == pytest.approx(1.5 / 2.4, rel=1e-12)
    weights = suite.file.run_score.weights
    assert max(weights, key=weights.get) == "xtrack_rmse"
    worse = run | {"xtrack_rmse": 0.5}
    assert suite.run_score(worse, "helix") - suite.run_score(run, "helix") == pytest.approx(0.5 / 2.4, rel=1e-12)
