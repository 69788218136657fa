"""``trajectory.csv`` values: Arrow's shortest round-trip text, whole numbers with ``.0``: every
float64 reads back to the same bits, every column reads back as floats, and the text is the
shortest that does so (no digit can be dropped)."""
from __future__ import annotations

import io

import numpy as np
import pandas as pd
from hypothesis import given
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from auvtrack.simulation.result import Result, csv_column

SPECIAL = np.array([0.0, -0.0, 1.0, -3.0, 0.1, 1e-5, 1e-7, 1e14, 1e15, 1e16, 1e20, 2.0 ** 53, 5e-324,
                    1.7976931348623157e308, np.nan, np.inf, -np.inf, 0.30000000000000004, 100.0, 1000.0])


def _texts(values: np.ndarray) -> list[str]:
    return [str(x) for x in csv_column(values).cast("string").to_pylist()]


def _bits(a: np.ndarray) -> np.ndarray:
    return np.ascontiguousarray(a, dtype=np.float64).view(np.uint64)


def _check(values: np.ndarray) -> None:
    texts = _texts(values)
    back = np.array([float(t) for t in texts])
    np.testing.assert_array_equal(_bits(back)[~np.isnan(values)], _bits(values)[~np.isnan(values)])
    assert np.isnan(back).tolist() == np.isnan(values).tolist()
    for x, t in zip(values.tolist(), texts):
        assert any(c in t for c in ".ein"), t  # never integer-looking: read back as a float
        if np.isfinite(x) and "e" not in t and "." in t:  # positional: no trailing digit can be dropped
            head, frac = t.split(".")
            if len(frac) > 1:
                assert float(head + "." + frac[:-1]) != x, t


def test_special_values_round_trip_and_read_as_floats():
    _check(SPECIAL)
    assert _texts(np.array([0.0, -0.0, 3.0, 0.5, np.inf])) == ["0.0", "-0.0", "3.0", "0.5", "inf"]


@given(arrays(np.float64, st.integers(1, 60), elements=st.floats(allow_nan=True, allow_infinity=True)))
def test_every_float64_round_trips_bit_exactly(values):
    _check(values)


def test_a_saved_csv_reads_back_as_float_columns_with_the_same_bits(tmp_path):
    n = SPECIAL.size
    channels = {"t": np.arange(n, dtype=float)}
    names = ["x", "y", "z", "theta", "psi", "u", "v", "w", "q", "r", "tau_u", "tau_q", "tau_r", "xd", "yd", "zd",
             "ex", "ey", "ez"]
    channels.update({name: (SPECIAL if i % 2 else np.zeros(n)) for i, name in enumerate(names)})
    folder = Result(channels, {}, "ok", None, {}).save(tmp_path / "run")
    text = (folder / "trajectory.csv").read_text()
    df = pd.read_csv(io.StringIO(text))
    assert all(dtype == np.float64 for dtype in df.dtypes)  # an all-zero column too
    back = Result.load(folder)
    for name, v in channels.items():
        np.testing.assert_array_equal(_bits(back[name])[~np.isnan(v)], _bits(v)[~np.isnan(v)])
