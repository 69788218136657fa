"""A plug-in outside the SIMD lane subset is said at set-up (a note), not found mid-batch."""
from __future__ import annotations

from pathlib import Path

import pytest

from auvtrack.engine.kernels import KernelKey
from auvtrack.simulation.compiling import lane_note

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "plugin_controller.py"
AUX = "    out.aux[0], out.aux[1], out.aux[2] = a\n"


def _law(tmp_path: Path, name: str, tuple_loop: bool) -> Path:
    text = EXAMPLE.read_text()
    assert AUX in text
    path = tmp_path / f"{name}.py"
    path.write_text(text.replace(AUX, "    for i, v in enumerate(a):\n        out.aux[i] = v\n") if tuple_loop else text)
    return path


def test_a_law_iterating_over_a_tuple_has_no_lane_form(tmp_path):
    key = KernelKey(str(_law(tmp_path, "tuple_law", True)), "auvtrack.plant.five_dof", "plugin on 5dof")
    note = lane_note(key)
    assert note is not None and note.startswith("plugin on 5dof: no SIMD lane form (")
    assert "only 'for name in range(...)' loops are supported" in note and note.endswith("runs it on threads")


def test_the_example_law_and_the_builtins_have_one(tmp_path):
    assert lane_note(KernelKey(str(_law(tmp_path, "example_law", False)), "auvtrack.plant.five_dof", "x")) is None
    assert lane_note(KernelKey("auvtrack.control.ftsmc", "auvtrack.plant.five_dof", "ftsmc on 5dof")) is None


@pytest.mark.slow
def test_check_prints_it_as_a_note(tmp_path, capsys):
    from auvtrack.cli import main

    _law(tmp_path, "tuple_law", True)
    scenario = tmp_path / "s.toml"
    scenario.write_text('[controller]\nkind = "plugin"\nmodule = "tuple_law.py"\n[sim]\nduration = 1.0\n')
    assert main(["check", str(scenario)]) == 0
    err = capsys.readouterr().err
    assert f"note: {tmp_path / 'tuple_law.py'}: plugin on 5dof: no SIMD lane form (" in err, err


def test_asking_twice_gives_the_same_answer(tmp_path):
    """The loop's lane form is not kept when a function it calls has none (a second ask must not find it)."""
    key = KernelKey(str(_law(tmp_path, "tuple_law_twice", True)), "auvtrack.plant.five_dof", "plugin on 5dof")
    first = lane_note(key)
    assert first is not None and lane_note(key) == first
