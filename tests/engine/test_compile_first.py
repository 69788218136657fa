"""Studies and ``reproduce`` compile their kernels first: the "compiling kernels" step, with its own
progress bar, comes before the work's progress bar and before any kernel is loaded (issue 14.1)."""
from __future__ import annotations

import sys

import pytest
import tqdm.auto

from auvtrack.scenario import load_scenario, paper_scenario_path
from auvtrack.simulation import compiling
from auvtrack.simulation import pipeline as api
from auvtrack.engine import kernels
from auvtrack.studies.registry import all_studies, kinds_in


class _Compiled(Exception):
    """Raised by the stand-in for kernels.warmup: the study reached its compile step."""

    def __init__(self, keys):
        super().__init__("compile step reached")
        self.keys = list(keys)


def _guard(monkeypatch):
    """Replace warmup by a recorder that stops the study, and fail on any earlier bar or kernel load."""
    def warmup(keys, **kw):
        raise _Compiled(keys)

    def too_early(*a, **k):
        pytest.fail("a progress bar or kernel came before the compile step")

    monkeypatch.setattr(kernels, "warmup", warmup)
    monkeypatch.setattr(kernels, "kernel", too_early)
    monkeypatch.setattr(kernels, "kernel_module", too_early)
    monkeypatch.setattr(tqdm.auto, "tqdm", too_early)
    for name, mod in list(sys.modules.items()):
        if name.startswith("auvtrack.studies.") and hasattr(mod, "tqdm"):
            monkeypatch.setattr(mod, "tqdm", too_early)


def test_reproduce_compiles_exactly_its_kernels_before_its_bar(monkeypatch, tmp_path):
    from auvtrack.studies import reproduce

    want = {api.prepare(load_scenario(paper_scenario_path(), [f"controller.kind={k}"])).key.name
            for _, k in reproduce.CONTROLLERS}
    _guard(monkeypatch)
    with pytest.raises(_Compiled) as got:
        reproduce.reproduce(tmp_path / "out", quick=True, progress=True)
    assert {k.name for k in got.value.keys} == want


@pytest.mark.parametrize("name", sorted(all_studies()))
def test_every_study_compiles_before_any_bar_or_kernel(name, monkeypatch, tmp_path):
    spec = all_studies()[name]
    _guard(monkeypatch)
    with pytest.raises(_Compiled) as got:
        spec.run(tmp_path / name, quick=True, progress=True)
    assert got.value.keys, "the compile step names the kernels it needs"


def test_kernel_keys_match_the_keys_runs_use():
    """A (controller, plant) pair gives the kernel that prepare() builds (5-DOF; each 6-DOF preset).

    One 6-DOF kernel serves every preset: the truth's equations are chosen by its packed parameters.
    """
    five = compiling.kernel_keys([("ftsmc", "5dof")])
    assert [k.name for k in five] == [api.prepare(load_scenario({}, ["controller.kind=ftsmc"])).key.name]
    six = {k.name for k in compiling.kernel_keys([("ftsmc", "6dof")])}
    for preset in ("remus100_prestero", "remus100_fossen"):
        sc = load_scenario({}, ["controller.kind=ftsmc", "plant.model=6dof", f"plant.preset={preset}",
                                "vehicle.preset=remus100"])
        assert api.prepare(sc).key.name in six
    assert len(six) == 1


def test_kinds_in():
    assert kinds_in(["controller.kind=fxtntsmc", "envelope.kind=rigid", "controller.kind = ftsmc",
                     "controller.kind=fxtntsmc"]) == ["fxtntsmc", "ftsmc"]
    assert kinds_in(["sim.duration=1"]) == []
