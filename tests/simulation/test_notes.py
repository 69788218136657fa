"""A default run does not warn: its set-up notes (the paper's initial envelope widening) are in
``Result.notes``, its summary and ``run.json``; ``warn=True`` still emits them as warnings."""
from __future__ import annotations

import warnings

import pytest

import auvtrack

SHORT = ["sim.duration=0.2"]


def test_the_default_paper_run_does_not_warn_and_keeps_its_note():
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # any warning fails the run
        res = auvtrack.simulate("paper", SHORT)
    assert res.ok
    assert len(res.notes) == 1 and res.notes[0].startswith("envelope: start at |e_y(0)|/rho1_y(0)")
    assert list(res.notes) == res.meta["notes"] and "1 note (.notes)" in repr(res)
    with pytest.warns(UserWarning, match=r"envelope: start at \|e_y\(0\)\|"):
        loud = auvtrack.simulate("paper", SHORT, warn=True)
    assert loud.notes == res.notes
