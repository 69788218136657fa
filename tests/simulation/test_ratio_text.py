"""The |e|/rho peaks in figure subtitles never round a value across 1 (0.9964 is not "1")."""
from __future__ import annotations

import math

from hypothesis import given
from hypothesis import strategies as st

from auvtrack.simulation.plotting import ratio_text


def test_known_values():
    assert ratio_text(0.9964) == "0.996"
    assert ratio_text(1.004) == "1.004"
    assert ratio_text(1.0) == "1"
    assert ratio_text(0.42) == "0.42" and ratio_text(37.2) == "37"
    assert ratio_text(math.inf) == "inf"


@given(st.floats(min_value=1e-9, max_value=1e9))
def test_the_text_stays_on_the_values_side_of_one(v):
    shown = float(ratio_text(v))
    assert (shown < 1.0) == (v < 1.0) and (shown > 1.0) == (v > 1.0)
    assert math.isclose(shown, v, rel_tol=0.06)  # two significant digits at least
