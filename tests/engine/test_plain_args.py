"""The project's dispatcher compiles callees for plain (unliteral) argument types and falls back to the
literal types when only those type, also once ``auvtrack.jit.errors`` is imported (the package's own
module of that name must not stand in for Numba's errors)."""
from __future__ import annotations

import numpy as np

import auvtrack.jit.errors  # noqa: F401 - imported, as every command line does
from auvtrack.jit import njit


@njit(cache=False)
def _pick(t, i):
    return t[i]  # a heterogeneous tuple: types only with a literal index


@njit(cache=False)
def _caller(t):
    return _pick(t, 1)


def test_a_callee_that_types_only_with_a_literal_falls_back_to_it():
    assert np.array_equal(_caller((1.0, np.arange(3.0))), np.arange(3.0))
