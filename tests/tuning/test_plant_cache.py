"""A tuning sets each run's plant up once: candidates prepared from the shared set-ups equal fresh ones bit for bit."""
from __future__ import annotations

import numpy as np
import pytest

from auvtrack.benchmark.suite import load_suite
from auvtrack.scenario import load_scenario
from auvtrack.simulation.pipeline import prepare
from auvtrack.tuning.objective import candidate_table, split_conditions, split_specs
from tiny_suite import TINY

from tuning_suite import SPLITS

SIXDOF = ("[tiers.truth6]\nrequires_plant = \"6dof\"\nstart = { lateral = 0.5 }\n"
          "[tiers.truth6.set]\n\"plant.model\" = \"6dof\"\n"
          "[tiers.truth6.cycle]\n\"plant.preset\" = [\"remus100_prestero\", \"remus100_fossen\"]\n")


@pytest.fixture(scope="module")
def suite(tmp_path_factory):
    path = tmp_path_factory.mktemp("suite") / "tiny6.toml"
    path.write_text(TINY + SIXDOF + SPLITS.replace('tasks = ["line"]\n[splits.validation]',
                                                  'tasks = ["line", "helix"]\n[splits.validation]', 1))
    return load_suite(path, check=False)


def _arrays(p) -> list[tuple[str, bytes, str, tuple]]:
    """Every array the kernel reads, with its name, bytes, dtype and shape."""
    out = []
    for name in ("plant", "controller", "environment", "settings"):
        bundle = getattr(p, name)
        for field in bundle._fields:
            a = np.asarray(getattr(bundle, field))
            out.append((f"{name}.{field}", a.tobytes(), str(a.dtype), a.shape))
    out.append(("ref_p", np.asarray(p.ref_p).tobytes(), str(np.asarray(p.ref_p).dtype), np.shape(p.ref_p)))
    return out


def test_candidates_prepared_from_shared_plant_setups_equal_fresh_ones(suite):
    conditions = split_conditions(suite, "training")
    assert {tier for _, tier, _, _ in conditions} >= {"calm", "truth6"}
    cache: dict = {}
    candidates = [{"kind": "pid"}, candidate_table({"kind": "pid"}, {"kp": 0.3, "ki": 0.01, "kd": 1.5, "kaw": 2.0})]
    for table in candidates:
        for spec in split_specs(suite, table, "training", conditions=conditions):
            sc = load_scenario(spec.raw, spec.overrides)
            cached, fresh = prepare(sc, plant_cache=cache), prepare(sc)
            assert _arrays(cached) == _arrays(fresh), (spec.task, spec.tier, spec.index)
            assert cached.notes == fresh.notes and cached.channels == fresh.channels
            assert cached.plant.x0 is not fresh.plant.x0
    runs = len(conditions)
    assert 0 < len(cache) <= runs  # the second candidate found every plant set up


def test_a_cached_set_up_gives_each_run_its_own_arrays(suite):
    spec = split_specs(suite, {"kind": "pid"}, "training")[-1]
    sc = load_scenario(spec.raw, spec.overrides)
    cache: dict = {}
    a, b = prepare(sc, plant_cache=cache), prepare(sc, plant_cache=cache)
    assert len(cache) == 1
    a.plant.x0[:] = np.nan  # a run that wrote into its arrays leaves the next run's alone
    assert not np.isnan(b.plant.x0).any() and not np.isnan(prepare(sc, plant_cache=cache).plant.x0).any()


def test_runs_with_other_conditions_are_set_up_again(suite):
    specs = split_specs(suite, {"kind": "pid"}, "training")
    cache: dict = {}
    for s in specs:
        prepare(load_scenario(s.raw, s.overrides), plant_cache=cache)
    distinct = {(s.task, s.tier, s.index) for s in specs}
    assert len(cache) == len(distinct)  # the seed and the start differ between every run of the split
