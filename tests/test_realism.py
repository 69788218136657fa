"""Realism ingredients (actuator saturation and rate limits, sensor noise) and the realism study."""
import json
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from auvtrack.environment.sensors import measure, noise_table
from auvtrack.plant.actuators import pack_actuator, rate_limit, saturate

finite = st.floats(-1e4, 1e4, allow_nan=False)
limit = st.one_of(st.floats(1e-3, 1e4), st.just(math.inf))


@given(st.tuples(finite, finite, finite), st.tuples(limit, limit, limit))
def test_saturation_is_the_projection_on_the_box(tau, lim):
    act = pack_actuator(lim, (math.inf,) * 3)
    out = saturate(tau, act)
    for x, y, m in zip(tau, out, lim):
        assert abs(y) <= m
        assert y == (x if abs(x) <= m else math.copysign(m, x))


@given(st.tuples(finite, finite, finite), st.tuples(finite, finite, finite), st.tuples(limit, limit, limit),
       st.floats(1e-3, 0.1))
def test_rate_limit_moves_at_most_rate_times_h_and_exactly_when_it_can(cmd, prev, rate, h):
    act = pack_actuator((math.inf,) * 3, rate)
    out = rate_limit(cmd, prev, act, h)
    for c, p, y, r in zip(cmd, prev, out, rate):
        ulp = 4 * np.finfo(float).eps * max(abs(p), abs(c))  # p +- r h is rounded once
        assert abs(y - p) <= r * h * (1 + 1e-12) + ulp
        if abs(c - p) <= r * h:
            assert y == c
        else:
            assert math.copysign(1.0, y - p) == math.copysign(1.0, c - p)


def test_pack_actuator_refuses_bad_limits():
    with pytest.raises(ValueError, match="must be > 0"):
        pack_actuator((1.0, 0.0, 1.0), (1.0, 1.0, 1.0))
    with pytest.raises(ValueError, match="3 values each"):
        pack_actuator((1.0, 1.0), (1.0, 1.0, 1.0))


def test_noise_is_seeded_scaled_and_independent_per_channel():
    sigma = np.array([0.01, 0.02, 0.03, 0.001, 0.002, 0.1, 0.2, 0.3, 0.01, 0.02])
    a, b = noise_table(7, 40_000, sigma), noise_table(7, 40_000, sigma)
    assert a.shape == (40_000, 10) and np.array_equal(a, b)
    assert not np.array_equal(a, noise_table(8, 40_000, sigma))
    np.testing.assert_allclose(a.std(axis=0), sigma, rtol=0.03)  # 40k samples: ~0.35 % std error
    np.testing.assert_allclose(a.mean(axis=0) / sigma, 0.0, atol=0.02)
    corr = np.corrcoef(a.T) - np.eye(10)
    assert np.abs(corr).max() < 0.03
    assert noise_table(7, 100, np.zeros(10)).shape == (0, 10)
    with pytest.raises(ValueError, match="sigma needs 10"):
        noise_table(7, 100, -sigma)


def test_measure_adds_row_k_and_nothing_without_noise():
    X = np.arange(12.0)
    noise = noise_table(3, 5, np.full(10, 0.5))
    eta, nu = measure(X, noise, 2)
    np.testing.assert_array_equal(np.array(eta + nu), X[:10] + noise[2])
    eta, nu = measure(X, np.zeros((0, 10)), 2)
    np.testing.assert_array_equal(np.array(eta + nu), X[:10])
