"""Docstrings follow numpydoc (checked with ``numpydoc.validate``, as python-control does).

Every public function and class of every module has a docstring with a one-line summary; the
user-facing API documents every parameter and its return value.  Compiled kernels share the
argument contract written once in their module docstring (e.g. :mod:`auvtrack.control.contract`),
so only the summary rules apply to them.
"""
import importlib
import inspect
import pkgutil

import pytest
from numpydoc.validate import validate

import auvtrack

# (SS05, "start with a verb", is left out: it misfires on noun summaries such as "Positions ...")
SUMMARY_RULES = {"GL08", "SS01", "SS03", "SS06"}
FULL_RULES = SUMMARY_RULES | {"PR01", "PR02", "PR03", "RT01", "RT03"}

API = [
    "auvtrack.simulation.pipeline.simulate",
    "auvtrack.simulation.pipeline.prepare",
    "auvtrack.simulation.pipeline.run_prepared",
    "auvtrack.scenario.loader.load_scenario",
    "auvtrack.scenario.overrides.parse_overrides",
    "auvtrack.scenario.catalog.available_scenarios",
    "auvtrack.scenario.catalog.scenario_path",
    "auvtrack.scenario.catalog.copy_scenario",
    "auvtrack.scenario.reading.read_bounded",
    "auvtrack.scenario.reading.override_value",
    "auvtrack.simulation.result.Result.to_pandas",
    "auvtrack.simulation.result.Result.plot",
    "auvtrack.simulation.result.Result.save",
    "auvtrack.control.fxtntsmc.theory.fixed_time_bounds",
    "auvtrack.control.fxtntsmc.theory.check_theorem1",
    "auvtrack.control.fxtntsmc.theory.lemma1_time",
    "auvtrack.control.fxtntsmc.theory.lemma1_residual",
    "auvtrack.control.registry.register",
    "auvtrack.control.registry.get",
    "auvtrack.control.registry.ControllerSpec.from_module",
    "auvtrack.plant.registry.register",
    "auvtrack.plant.registry.get",
    "auvtrack.plant.registry.PlantSpec.from_module",
    "auvtrack.engine.kernels.kernel",
    "auvtrack.engine.kernels.warmup",
    "auvtrack.user_modules.load_module",
    "auvtrack.batch.runner.run_batch",
    "auvtrack.reference.build_reference",
    "auvtrack.environment.build_disturbance",
    "auvtrack.vehicle.presets.get_preset",
    "auvtrack.studies.reproduce.reproduce",
    "auvtrack.studies.registry.all_studies",
    "auvtrack.studies.registry.get_study",
    "auvtrack.benchmark.compare.compare",
    "auvtrack.benchmark.suite.load_suite",
    "auvtrack.benchmark.suite.resolve_controllers",
    "auvtrack.benchmark.statistics.wilson_interval",
    "auvtrack.benchmark.statistics.wilson_halfwidth_max",
    "auvtrack.benchmark.statistics.bootstrap_median",
    "auvtrack.benchmark.statistics.wilcoxon_test",
    "auvtrack.benchmark.statistics.sign_test",
    "auvtrack.benchmark.statistics.holm",
    "auvtrack.benchmark.statistics.rank_biserial",
    "auvtrack.benchmark.statistics.average_ranks",
    "auvtrack.benchmark.leaderboard.score_table",
    "auvtrack.benchmark.leaderboard.cell_statistics",
    "auvtrack.benchmark.leaderboard.rank_bootstrap",
    "auvtrack.benchmark.leaderboard.paired_comparisons",
    "auvtrack.benchmark.execute.execute",
    "auvtrack.benchmark.execute.run_chunk",
    "auvtrack.feasibility.assess.assess",
    "auvtrack.feasibility.steady.tightest_turn",
    "auvtrack.feasibility.demands.reference_demands",
    "auvtrack.feasibility.demands.current_bound",
    "auvtrack.benchmark.execute.run_planned",
    "auvtrack.benchmark.execute.plan_runs",
    "auvtrack.benchmark.execute.check_plan",
    "auvtrack.batch.executor.execute_chunks",
    "auvtrack.batch.executor.check_workers",
    "auvtrack.batch.chunk_files.check_chunk",
    "auvtrack.batch.chunk_files.table_digest",
    "auvtrack.batch.chunk_files.write_chunk",
    "auvtrack.batch.scheduler.connect_scheduler",
    "auvtrack.batch.scheduler.probe_scheduler",
    "auvtrack.batch.sweep.run_sweep",
]


def _public_objects():
    for info in pkgutil.walk_packages(auvtrack.__path__, "auvtrack."):
        mod = importlib.import_module(info.name)
        for name, obj in vars(mod).items():
            if name.startswith("_") or getattr(obj, "__module__", None) != mod.__name__:
                continue
            if inspect.isfunction(obj) or inspect.isclass(obj) or hasattr(obj, "py_func"):
                yield f"{mod.__name__}.{name}"


def _errors(path, rules):
    return [f"{code}: {msg}" for code, msg in validate(path)["errors"] if code in rules]


def test_the_walk_finds_the_package():
    names = list(_public_objects())
    assert len(names) > 100 and "auvtrack.simulation.pipeline.simulate" in names


def test_every_public_object_has_a_numpydoc_summary():
    bad = {p: e for p in _public_objects() if (e := _errors(p, SUMMARY_RULES))}
    assert not bad, "\n".join(f"{p}: {e}" for p, e in bad.items())


@pytest.mark.parametrize("path", API)
def test_user_facing_api_is_fully_documented(path):
    assert _errors(path, FULL_RULES) == []
