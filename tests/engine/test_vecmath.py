"""Fast forms of the hot path against their readable forms: vector libm calls (auvtrack.jit.vecmath), the law using them, the fused RBF update."""
from __future__ import annotations

import math
import os
import subprocess
import sys
from pathlib import Path

import numba
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from auvtrack import jit as _jit
from auvtrack.jit import vecmath as _vecmath
from auvtrack.jit.vecmath import atanh4, exp8, pow4, sincos4
from auvtrack.control import fxtntsmc
from auvtrack.control.fxtntsmc import rbf

ROOT = Path(__file__).resolve().parents[2]
MAX_ULP = 4  # glibc's bound for libmvec (manual, "Errors in Math Functions")


@numba.njit(error_model="numpy")
def _pow4_array(x, p, out):
    for i in range(0, x.shape[0], 4):
        out[i], out[i + 1], out[i + 2], out[i + 3] = pow4((x[i], x[i + 1], x[i + 2], x[i + 3]),
                                                          (p[i], p[i + 1], p[i + 2], p[i + 3]))


@numba.njit(error_model="numpy")
def _exp8_array(x, out):
    for i in range(0, x.shape[0], 8):
        r = exp8((x[i], x[i + 1], x[i + 2], x[i + 3], x[i + 4], x[i + 5], x[i + 6], x[i + 7]))
        for k in range(8):
            out[i + k] = r[k]


@numba.njit(error_model="numpy")
def _scalar_pow4(x, p):
    return _vecmath._pow4_scalar(x, p)


@numba.njit(error_model="numpy")
def _scalar_exp8(x):
    return _vecmath._exp8_scalar(x)


@numba.njit(error_model="numpy")
def _powers_below3(x, p, need):
    return fxtntsmc.powers_below3(x, p, need)


def test_backend_is_vector_where_libmvec_exists():
    """With glibc's libmvec (all its symbols), AVX2 and a host compile target the vector calls are used (this CI machine)."""
    import ctypes.util

    import llvmlite.binding as ll

    lib = ctypes.util.find_library("mvec") if sys.platform.startswith("linux") else None
    expected_vector = (lib is not None and all(hasattr(ctypes.CDLL(lib), n) for n in _vecmath.SYMBOLS)
                       and ll.get_host_cpu_features().get("avx2", False)
                       and numba.config.CPU_NAME in (None, "host")
                       and os.environ.get("AUVTRACK_LIBMVEC", "1") != "0")
    assert (_vecmath.BACKEND != "scalar") == expected_vector
    assert _vecmath.BACKEND in ("avx2", "scalar")


def test_cache_directory_names_the_backend():
    assert _jit.cache_dir().name.endswith("-" + _vecmath.BACKEND + ("-avx512" if _vecmath.WIDE else ""))


def test_the_lane_kernels_8_lane_calls_select_another_cache_directory():
    """AUVTRACK_LIBMVEC_AVX512=0 changes the lane kernels' code (4-lane calls only), so their cache too."""
    code = "import auvtrack.jit.vecmath as v, auvtrack.jit as j; print(len(v.WIDE), j.cache_dir().name)"
    names = {}
    for flag in ("0", "1"):
        out = subprocess.run([sys.executable, "-c", code], env={**os.environ, "AUVTRACK_LIBMVEC_AVX512": flag},
                             capture_output=True, text=True, check=True).stdout.split()
        names[flag] = (int(out[0]), out[1])
    assert names["0"][0] == 0 and not names["0"][1].endswith("-avx512")
    assert names["1"][1].endswith("-avx512") == (names["1"][0] > 0)
    assert (names["0"][1] != names["1"][1]) == (names["1"][0] > 0)


def test_libmvec_can_be_switched_off():
    """AUVTRACK_LIBMVEC=0 selects the scalar loops (and therefore another cache directory)."""
    code = "import auvtrack.jit.vecmath as v, auvtrack.jit as j; print(v.BACKEND, j.cache_dir().name)"
    out = subprocess.run([sys.executable, "-c", code], env={**os.environ, "AUVTRACK_LIBMVEC": "0"},
                         capture_output=True, text=True, check=True).stdout.split()
    assert out[0] == "scalar" and out[1].endswith("-scalar")  # (no 8-lane calls without libmvec)


@settings(max_examples=60, deadline=None)
@given(st.lists(st.floats(1e-12, 1e6), min_size=4, max_size=4),
       st.lists(st.floats(-3.0, 3.0), min_size=4, max_size=4))
def test_pow4_matches_numpy_power(x, p):
    x, p = np.array(x), np.array(p)
    out = np.empty(4)
    _pow4_array(x, p, out)
    np.testing.assert_array_max_ulp(out, np.power(x, p), maxulp=MAX_ULP)


def test_pow4_on_many_bases_and_the_law_exponents():
    rng = np.random.default_rng(3)
    x = np.concatenate([rng.uniform(1e-9, 1.0, 4000), rng.uniform(1.0, 50.0, 4000)])
    for q in (-0.2, -0.4, 0.5, 1.0, 2.5):  # a2 - 1 and alpha - 1 of Section 4 among them
        out = np.empty_like(x)
        _pow4_array(x, np.full_like(x, q), out)
        np.testing.assert_array_max_ulp(out, np.power(x, q), maxulp=MAX_ULP)


def test_pow4_edge_values_follow_ieee_pow():
    x = np.array([0.0, 0.0, 1.0, np.inf])
    p = np.array([-0.2, 0.5, -0.4, -0.2])
    out = np.empty(4)
    _pow4_array(x, p, out)
    np.testing.assert_array_equal(out, [np.inf, 0.0, 1.0, 0.0])


@settings(max_examples=60, deadline=None)
@given(st.lists(st.floats(-700.0, 700.0), min_size=8, max_size=8))
def test_exp8_matches_numpy_exp(x):
    x = np.array(x)
    out = np.empty(8)
    _exp8_array(x, out)
    np.testing.assert_array_max_ulp(out, np.exp(x), maxulp=MAX_ULP)


def test_exp8_underflows_to_zero_like_exp():
    x = np.array([-800.0, -745.2, 0.0, -1e-300, -50.0, -1e3, -np.inf, 1.0])
    out = np.empty(8)
    _exp8_array(x, out)
    ref = np.exp(x)
    np.testing.assert_array_max_ulp(out, ref, maxulp=MAX_ULP)
    assert out[0] == 0.0 and out[5] == 0.0 and out[6] == 0.0 and out[2] == 1.0


def test_scalar_fallback_is_libm_bit_for_bit():
    x, p = (0.3, 1.7, 1e-6, 4.0), (-0.2, -0.4, 0.8, 1.0)
    assert _scalar_pow4(x, p) == tuple(a**b for a, b in zip(x, p))
    y = (-1.0, -0.5, 0.0, 0.25, -30.0, -700.0, 3.0, -1e-9)
    assert _scalar_exp8(y) == tuple(math.exp(v) for v in y)


@settings(max_examples=80, deadline=None)
@given(st.tuples(st.floats(1e-9, 10.0), st.floats(1e-9, 10.0), st.floats(1e-9, 10.0)),
       st.sampled_from([0.6, 0.8, 0.5756, 1.5, 2.0]),
       st.tuples(st.booleans(), st.booleans(), st.booleans()))
def test_powers_below3_pins_to_power_below(x, p, need):
    """One needed lane: exactly power_below, the others 1.  Two or more: every lane within 4 ulp of it.  p = 2: x."""
    q = _powers_below3(x, p, need)
    if p == 2.0:
        assert q == x
        return
    for k in range(3):
        ref = fxtntsmc.power_below.py_func(x[k], p)
        if sum(need) >= 2:
            np.testing.assert_array_max_ulp(q[k], ref, maxulp=MAX_ULP)
        elif need[k]:
            assert q[k] == ref
        else:
            assert q[k] == 1.0


@numba.njit(error_model="numpy")
def _basis(e, ed, cp, m, width, psi):
    rbf.basis(e, ed, cp, 0, m, width, psi)


@pytest.mark.parametrize("m", [1, 7, 8, 9, 20])
def test_rbf_basis_matches_eq12_for_any_neuron_count(m):
    """psi_j = exp(-||x - c_j||^2 / (2 b^2)) within 4 ulp, padding lanes never written."""
    rng = np.random.default_rng(m)
    centres = rng.uniform(-1.0, 1.0, (m, 6))
    e, ed = tuple(rng.normal(size=3)), tuple(rng.normal(size=3))
    psi = np.full(m + 8, -1.0)
    _basis(e, ed, centres.ravel(), m, 1.3, psi)
    inv = 1.0 / (2.0 * 1.3 * 1.3)
    ref = []
    for c in centres:  # the kernel's order of summation, so that only exp may differ
        d2 = 0.0
        for k in range(3):
            d2 += (e[k] - c[k]) ** 2 + (ed[k] - c[3 + k]) ** 2
        ref.append(math.exp(-d2 * inv))
    np.testing.assert_array_max_ulp(psi[:m], np.array(ref), maxulp=MAX_ULP)
    assert np.all(psi[m:] == -1.0)


def _law_points(tmp_path, backend_env: str, given=None) -> dict:
    out = tmp_path / f"law-{backend_env}.npz"
    subprocess.run([sys.executable, str(ROOT / "tests" / "law_points.py"), str(out)] + ([str(given)] if given else []),
                   check=True, env={**os.environ, "AUVTRACK_LIBMVEC": backend_env,
                                    "PYTHONPATH": os.pathsep.join(filter(None, [str(ROOT), os.environ.get("PYTHONPATH")]))},
                   cwd=ROOT)
    return dict(np.load(out))


@pytest.mark.skipif(_vecmath.BACKEND == "scalar", reason="only one back end on this machine")
def test_vector_law_matches_the_libm_law(tmp_path):
    """The FXTNTSMC law with libmvec equals the libm (scalar) law to 1e-14 of each output's scale.

    3000 seeded states over the envelope, both branches of eq. (27) and of the nonsingular
    surface on every axis, each back end compiled in its own process.
    """
    vec = _law_points(tmp_path, "1")
    ref = _law_points(tmp_path, "0", given=tmp_path / "law-1.npz")
    assert np.array_equal(vec["Xs"], ref["Xs"]) and np.all(ref["status"] == 0) and np.all(vec["status"] == 0)
    z = ref["auxs"][:, 15:18]
    assert 0.1 < np.mean(np.abs(z) <= 0.01) < 0.9  # both branches of the surface are exercised
    se = np.array([fxtntsmc.surface(v, 0.8, 0.8, 0.8, 2.0, False, 0.01, 1e-6)[0] for v in z.ravel()])
    assert 0.1 < np.mean(np.abs(se) > 0.005) < 0.9  # and both of eq. (27)
    for key in ("taus", "dXs", "auxs"):
        scale = np.abs(ref[key]).max(axis=0)
        assert np.all(np.abs(vec[key] - ref[key]) <= 1e-14 * scale), key
    assert not np.array_equal(vec["taus"], ref["taus"])  # the two back ends really differ


@numba.njit(error_model="numpy")
def _sincos4_array(x, s_out, c_out):
    for i in range(0, x.shape[0], 4):
        s, c = sincos4((x[i], x[i + 1], x[i + 2], x[i + 3]))
        for k in range(4):
            s_out[i + k], c_out[i + k] = s[k], c[k]


@numba.njit(error_model="numpy")
def _atanh4_array(x, out):
    for i in range(0, x.shape[0], 4):
        out[i], out[i + 1], out[i + 2], out[i + 3] = atanh4((x[i], x[i + 1], x[i + 2], x[i + 3]))


def test_sincos4_matches_numpy_on_angles_and_disturbance_arguments():
    rng = np.random.default_rng(5)
    x = np.concatenate([rng.uniform(-np.pi, np.pi, 4000), rng.uniform(0.0, 200.0, 4000),  # 0.2 pi t, t <= 300 s
                        [0.0, -0.0, 1e-300, np.pi / 2]])
    x = np.concatenate([x, np.zeros(-x.size % 4)])
    s, c = np.empty_like(x), np.empty_like(x)
    _sincos4_array(x, s, c)
    # ulps relative to the magnitude 1 of sin and cos (near a zero the relative error is meaningless)
    assert np.max(np.abs(s - np.sin(x))) <= MAX_ULP * np.spacing(1.0)
    assert np.max(np.abs(c - np.cos(x))) <= MAX_ULP * np.spacing(1.0)
    big = np.abs(np.sin(x)) > 0.5
    np.testing.assert_array_max_ulp(s[big], np.sin(x[big]), maxulp=MAX_ULP)
    big = np.abs(np.cos(x)) > 0.5
    np.testing.assert_array_max_ulp(c[big], np.cos(x[big]), maxulp=MAX_ULP)


def test_atanh4_matches_numpy_over_the_envelope_ratio():
    rng = np.random.default_rng(6)
    x = np.concatenate([10.0 ** rng.uniform(-12, 0, 4000) * rng.choice([-1, 1], 4000),
                        rng.uniform(-0.999999, 0.999999, 4000), [0.0, -0.0, 0.5, -0.5]])
    out = np.empty_like(x)
    _atanh4_array(x, out)
    np.testing.assert_array_max_ulp(out, np.arctanh(x), maxulp=MAX_ULP)


def test_attitude_is_within_4_ulp_of_libm():
    from auvtrack.vehicle.kinematics import attitude

    for th, ps in ((0.0, 0.0), (0.3, -2.0), (-1.4, 3.1), (1e-8, 100.0)):
        got = np.array(attitude(th, ps))
        want = np.array([math.cos(th), math.sin(th), math.cos(ps), math.sin(ps)])
        assert np.max(np.abs(got - want)) <= MAX_ULP * np.spacing(1.0)


@numba.njit(error_model="numpy")
def _adapt_per_axis(X, off, m, psi, S, gain, dX):
    out = np.zeros(3)
    for i in range(3):
        out[i] = rbf.estimate_and_adapt(X, off + i * m, m, psi, S[i], gain[i], dX)
    return out


@numba.njit(error_model="numpy")
def _adapt_fused(X, off, m, psi, S, gain, dX):
    c = rbf.estimate_and_adapt3(X, off, m, psi, (S[0], S[1], S[2]), (gain[0], gain[1], gain[2]), dX)
    return np.array([c[0], c[1], c[2]])


@settings(max_examples=40, deadline=None)
@given(st.integers(1, 20), st.integers(0, 2**32 - 1))
def test_fused_estimator_update_is_the_per_axis_one_bit_for_bit(m, seed):
    """estimate_and_adapt3 (the law's form) equals three estimate_and_adapt calls (eq. 33-34) exactly."""
    rng = np.random.default_rng(seed)
    off = 13
    X = rng.normal(size=off + 3 * m + 2)
    psi, S, gain = rng.uniform(0, 1, m), rng.normal(size=3), rng.uniform(0.5, 50, 3)
    d1, d2 = np.full_like(X, np.nan), np.full_like(X, np.nan)
    c1 = _adapt_per_axis(X, off, m, psi, S, gain, d1)
    c2 = _adapt_fused(X, off, m, psi, S, gain, d2)
    assert np.array_equal(c1, c2)
    assert np.array_equal(d1, d2, equal_nan=True)  # same slots written, the others untouched
    assert np.isnan(d1[:off]).all() and not np.isnan(d1[off:off + 3 * m]).any()


def _vector_array_call(name: str, lanes: int, nargs: int):
    """A compiled loop calling the vector-ABI function ``name`` (``lanes`` wide) on rows of an array."""
    from llvmlite import ir
    from numba import types
    from numba.core import cgutils
    from numba.extending import intrinsic

    @intrinsic
    def call(typingctx, x, out):
        def codegen(context, builder, sig, args):
            xa = context.make_array(sig.args[0])(context, builder, args[0])
            oa = context.make_array(sig.args[1])(context, builder, args[1])
            vty = ir.VectorType(ir.DoubleType(), lanes)
            fn = cgutils.get_or_insert_function(builder.module, ir.FunctionType(vty, [vty] * nargs), name)
            rows = builder.extract_value(xa.shape, 0)
            i64 = ir.IntType(64)
            with cgutils.for_range(builder, rows) as loop:
                vals = []
                for a in range(nargs):
                    off = builder.add(builder.mul(loop.index, ir.Constant(i64, nargs * lanes)), ir.Constant(i64, a * lanes))
                    vals.append(builder.load(builder.bitcast(builder.gep(xa.data, [off]), vty.as_pointer()), align=8))
                dst = builder.gep(oa.data, [builder.mul(loop.index, ir.Constant(i64, lanes))])
                builder.store(builder.call(fn, vals), builder.bitcast(dst, vty.as_pointer()), align=8)
            return context.get_dummy_value()

        return types.none(x, out), codegen

    @numba.njit
    def run(x, out):
        call(x, out)

    return run


@pytest.mark.skipif(not _vecmath.WIDE, reason="no AVX-512 forms of the libmvec functions on this machine")
@pytest.mark.parametrize("narrow", sorted(_vecmath.WIDE_PAIRS))
def test_avx512_forms_return_the_bits_of_the_avx2_forms(narrow):
    """The 8-lane lane kernels evaluate pow, exp, sin, cos 8 runs per AVX-512 call: the same bits as the
    4-lane AVX2 calls of single runs, or the SIMD back end would not reproduce single runs."""
    wide = _vecmath.WIDE_PAIRS[narrow]
    nargs = 2 if "vv" in narrow else 1
    rng = np.random.default_rng(5)
    n = 8 * 12500
    specials = np.array([0.0, -0.0, 1e-310, -1e-310, 5e-324, 1.0, -1.0, 0.5, 2.0, 700.0, -745.0, 1e300, np.inf, -np.inf,
                         np.nan, 1e-8, math.pi, -math.pi, 1e6, 3e9])
    if nargs == 2:
        base = np.concatenate([rng.uniform(0.0, 3.0, n // 2), 10.0 ** rng.uniform(-300, 300, n // 2)])
        base[: specials.size] = np.abs(specials)
        expo = np.concatenate([rng.uniform(-1.0, 2.0, n // 2), rng.uniform(-50, 50, n // 2)])
        expo[specials.size: 2 * specials.size] = specials
        args = [base, rng.permutation(expo)]
    else:
        lo, hi = {"exp": (-745.0, 710.0)}.get(narrow.split("_")[-1], (-1e4, 1e4))
        x = np.concatenate([rng.uniform(-3.0, 3.0, n // 2), rng.uniform(lo, hi, n // 2)])
        x[: specials.size] = specials
        args = [x]

    def layout(w):
        return np.ascontiguousarray(np.stack([a.reshape(-1, w) for a in args], 1).reshape(-1, nargs * w))

    got4, got8 = np.zeros(n), np.zeros(n)
    _vector_array_call(narrow, 4, nargs)(layout(4), got4)
    _vector_array_call(wide, 8, nargs)(layout(8), got8)
    np.testing.assert_array_equal(got8.view(np.int64), got4.view(np.int64))
