"""Several libm calls in one (pow, exp, sin/cos, atanh on 4 lanes) for the compiled laws.

Each RK4 stage of the FXTNTSMC needs z_i = atanh(xi_i), |z_i|^(a2-1) and |S_e,i|^(alpha-1)
for the three axes (eq. 17, 27-28) and exp for each RBF neuron (eq. 12).  Called one at a
time, libm functions were about half of a step (``benchmarks/profile.md``).  glibc's vector
math library (libmvec, Linux x86-64) evaluates 4 lanes in about the time of one or two scalar
calls, so these functions call it directly:

* ``_ZGVdN4vv_pow`` (AVX2, 4 lanes) for :func:`pow4`;
* two ``_ZGVdN4v_exp`` (AVX2, 4 lanes) for :func:`exp8` (libmvec's 8-lane AVX-512 exp gives the same
  numbers but was slower here, ``benchmarks/profile.md``);
* ``_ZGVdN4v_sin`` and ``_ZGVdN4v_cos`` (AVX2, 4 lanes) for :func:`sincos4`: the attitude
  (theta, psi) of every stage and the two arguments of the paper's disturbance;
* ``_ZGVdN4v_atanh`` (AVX2, 4 lanes, glibc >= 2.35) for :func:`atanh4`: z of eq. (17), three axes.

libmvec's results are within 4 ulp of the correctly rounded value (glibc manual, "Errors in
Math Functions"), so they can differ from the scalar libm in the last bits:
``tests/engine/test_vecmath.py`` pins each function to NumPy within 4 ulp, and the law using them to the
libm law within 1e-14 of each output's scale.  Without libmvec, without
AVX2 on the compile target, or with ``AUVTRACK_LIBMVEC=0`` the same functions are scalar
loops over libm (bit-identical to the code before this module).  :data:`BACKEND` names the
choice, made once at import; the Numba cache directory includes it (``_jit.cache_dir``).
"""
from __future__ import annotations

import ctypes.util
import math
import os
import sys

import numba
from numba import types
from numba.core import cgutils
from numba.extending import intrinsic

__all__ = ["BACKEND", "pow4", "exp8", "sincos4", "atanh4", "backend"]

SYMBOLS = ("_ZGVdN4vv_pow", "_ZGVdN4v_exp", "_ZGVdN4v_sin", "_ZGVdN4v_cos", "_ZGVdN4v_atanh")
F4 = types.UniTuple(types.float64, 4)
F8 = types.UniTuple(types.float64, 8)


def backend() -> str:
    """Which implementation this process can use: "avx2" (libmvec) or "scalar"."""
    if os.environ.get("AUVTRACK_LIBMVEC", "1") == "0" or not sys.platform.startswith("linux"):
        return "scalar"
    if numba.config.CPU_NAME not in (None, "host"):  # a portable target may lack the vector ABI
        return "scalar"
    import llvmlite.binding as ll

    features = ll.get_host_cpu_features()
    if not features.get("avx2", False):
        return "scalar"
    lib = ctypes.util.find_library("mvec")
    if lib is None:
        return "scalar"
    try:
        handle = ctypes.CDLL(lib)
        if not all(hasattr(handle, name) for name in SYMBOLS):
            return "scalar"  # e.g. glibc < 2.35 has no vector atanh
        ll.load_library_permanently(lib)
    except (OSError, RuntimeError):  # pragma: no cover - a libmvec that cannot be loaded
        return "scalar"
    return "avx2"


BACKEND = backend()


def _lane_signature(width: int, args) -> types.Type | None:
    """Signature of a vector call on tuples whose entries are lane values (:mod:`auvtrack.jit.lane_values`).

    Each of the ``width`` entries of each argument may be a float or lanes (L runs); the result has
    lanes in every entry.  Returns None when no argument holds lanes (the scalar signature applies).
    """
    from .lane_values import Lanes

    counts = set()
    for a in args:
        if not (isinstance(a, types.BaseTuple) and len(a) == width):
            return None
        for t in a.types:
            if isinstance(t, Lanes):
                if t.dtype != types.float64:
                    return None
                counts.add(t.count)
            elif not isinstance(t, (types.Float, types.Integer)):
                return None
    if len(counts) != 1:
        return None
    L = counts.pop()
    if L % 4:
        return None
    return types.UniTuple(Lanes(types.float64, L), width)(*args)


WIDE_PAIRS = {"_ZGVdN4vv_pow": "_ZGVeN8vv_pow", "_ZGVdN4v_exp": "_ZGVeN8v_exp", "_ZGVdN4v_sin": "_ZGVeN8v_sin",
              "_ZGVdN4v_cos": "_ZGVeN8v_cos"}
"""4-lane AVX2 libmvec functions and their 8-lane AVX-512 forms that return the same bits (glibc 2.36,
``tests/engine/test_vecmath.py`` on 10^5 inputs each, specials included); the 8-lane ``atanh`` does not, so
it is not here.  Used by lane kernels of 8 runs (:mod:`auvtrack.jit.lane_values`): one call per 8 runs."""


def _wide() -> dict[str, str]:
    if BACKEND != "avx2" or os.environ.get("AUVTRACK_LIBMVEC_AVX512", "1") == "0":
        return {}
    import llvmlite.binding as ll

    if not ll.get_host_cpu_features().get("avx512f", False):
        return {}
    handle = ctypes.CDLL(ctypes.util.find_library("mvec"))
    return {k: v for k, v in WIDE_PAIRS.items() if hasattr(handle, v)}


WIDE = _wide()
"""The pairs of :data:`WIDE_PAIRS` this machine can use (empty: no AVX-512, or libmvec lacks them)."""


def _lane_call(name: str, width: int):
    """Codegen of :func:`_vector_call` on lane values: entry k of every argument is one vector of L runs,
    evaluated 4 runs per call of ``name`` (the same 4-lane function, so each run gets the value it
    gets in a single run).  The calls are declared without side effects, so an entry whose result
    is unused (the padding of ``(x, y, z, 1.0)``) is removed by LLVM.

    When every lane holds the same bits in every entry (a time and parameters shared by the runs
    of a block: the paper's disturbance), the entries of lane 0 take the single run's own call
    (``width / 4`` calls in all) and every lane gets its result: the same bits, as the functions
    are elementwise.
    """
    from llvmlite import ir

    from .lane_values import Lanes, _same_in_every_lane, _splat

    def codegen(context, builder, signature, args):
        rty = signature.return_type.types[0]
        L = rty.count
        lt = Lanes(types.float64, L)
        wide = WIDE.get(name) if L % 8 == 0 else None
        w = 8 if wide else 4
        vw = ir.VectorType(ir.DoubleType(), w)
        fn = cgutils.get_or_insert_function(builder.module, ir.FunctionType(vw, [vw] * len(args)), wide or name)
        fn.attributes.add("nounwind")
        fn.attributes.add("readnone")
        entries = [[(builder.extract_value(a, k), aty.types[k]) for a, aty in zip(args, signature.args)]
                   for k in range(width)]
        same = _same_in_every_lane(builder, [v for e in entries for v, t in e if isinstance(t, Lanes)], L)
        with builder.if_else(same) as (uniform, varied):
            with uniform:
                outs_u = _uniform_entries(context, builder, name, entries, len(args), L)
                bb_u = builder.block
            with varied:
                outs_v = []
                for e in entries:
                    vecs = [_splat(context, builder, v, t, lt) for v, t in e]
                    outs_v.append(_chunked_call(builder, fn, vecs, w, L))
                bb_v = builder.block
        outs = []
        for u, v in zip(outs_u, outs_v):
            phi = builder.phi(u.type)
            phi.add_incoming(u, bb_u)
            phi.add_incoming(v, bb_v)
            outs.append(phi)
        return context.make_tuple(builder, signature.return_type, outs)

    return codegen


def _chunked_call(builder, fn, vecs, w: int, L: int):
    """``fn`` (w lanes) on L-lane vectors, w lanes per call, the results concatenated."""
    from llvmlite import ir

    res = None
    for c in range(L // w):
        idx = ir.Constant(ir.VectorType(ir.IntType(32), w), list(range(w * c, w * c + w)))
        r = builder.call(fn, [builder.shuffle_vector(v, v, idx) for v in vecs])
        if res is None:
            res = r
        else:  # concatenate: [res, r] (res covers w c lanes)
            n = w * c
            r_wide = builder.shuffle_vector(r, r, ir.Constant(ir.VectorType(ir.IntType(32), n),
                                                                 [i % w for i in range(n)]))
            res = builder.shuffle_vector(res, r_wide, ir.Constant(ir.VectorType(ir.IntType(32), n + w),
                                                                     list(range(n)) + list(range(n, n + w))))
    return res


def _uniform_entries(context, builder, name: str, entries, nargs: int, L: int):
    """The single run's call of the 4-lane ``name`` on lane 0 of each entry, each result broadcast to L lanes."""
    from llvmlite import ir

    from .lane_values import Lanes, _broadcast

    v4 = ir.VectorType(ir.DoubleType(), 4)
    fn = cgutils.get_or_insert_function(builder.module, ir.FunctionType(v4, [v4] * nargs), name)
    fn.attributes.add("nounwind")
    fn.attributes.add("readnone")
    zero = ir.Constant(ir.IntType(32), 0)
    firsts = [[builder.extract_element(v, zero) if isinstance(t, Lanes)
               else context.cast(builder, v, types.unliteral(t), types.float64) for v, t in e] for e in entries]
    outs = []
    for part in range(len(entries) // 4):
        vecs = []
        for j in range(nargs):
            vec = ir.Constant(v4, ir.Undefined)
            for k in range(4):
                vec = builder.insert_element(vec, firsts[4 * part + k][j], ir.Constant(ir.IntType(32), k))
            vecs.append(vec)
        r = builder.call(fn, vecs)
        vL = ir.VectorType(ir.DoubleType(), L)
        outs += [_broadcast(builder, builder.extract_element(r, ir.Constant(ir.IntType(32), k)), vL, L)
                 for k in range(4)]
    return outs


def _vector_call(name: str, width: int, nargs: int, parts: int = 1):
    """Codegen calling the vector-ABI function ``name`` on ``nargs`` tuples of ``width`` floats.

    ``parts`` > 1 splits each tuple into that many calls of ``width // parts`` lanes.
    """
    from llvmlite import ir

    lanes = width // parts

    def codegen(context, builder, signature, args):
        vty = ir.VectorType(ir.DoubleType(), lanes)
        fn = cgutils.get_or_insert_function(builder.module, ir.FunctionType(vty, [vty] * nargs), name)
        outs = []
        for part in range(parts):
            vecs = []
            for a in args:
                v = ir.Constant(vty, ir.Undefined)
                for k in range(lanes):
                    v = builder.insert_element(v, builder.extract_value(a, part * lanes + k),
                                               ir.Constant(ir.IntType(32), k))
                vecs.append(v)
            r = builder.call(fn, vecs)
            outs += [builder.extract_element(r, ir.Constant(ir.IntType(32), k)) for k in range(lanes)]
        return context.make_tuple(builder, signature.return_type, outs)

    return codegen


# libmvec, AVX2 vector ABI: one call per 4 lanes.  With lane values (several runs at once,
# auvtrack.jit.lane_values) each entry of the tuple is a vector of runs, 4 runs per call (_lane_call).
def _typed(name: str, width: int, sig, parts: int = 1):
    def typer(typingctx, *args):
        lane_sig = _lane_signature(width, args)
        if lane_sig is not None:
            return lane_sig, _lane_call(name, width)
        return sig, _vector_call(name, width, len(args), parts)
    return typer


@intrinsic
def _pow4_libmvec(typingctx, x, p):
    return _typed("_ZGVdN4vv_pow", 4, F4(F4, F4))(typingctx, x, p)


@intrinsic
def _exp8_libmvec(typingctx, x):
    return _typed("_ZGVdN4v_exp", 8, F8(F8), parts=2)(typingctx, x)


@intrinsic
def _sin4_libmvec(typingctx, x):
    return _typed("_ZGVdN4v_sin", 4, F4(F4))(typingctx, x)


@intrinsic
def _cos4_libmvec(typingctx, x):
    return _typed("_ZGVdN4v_cos", 4, F4(F4))(typingctx, x)


@intrinsic
def _atanh4_libmvec(typingctx, x):
    return _typed("_ZGVdN4v_atanh", 4, F4(F4))(typingctx, x)


@numba.njit(inline="always", _nrt=False, error_model="numpy")
def _sincos4_libmvec(x):
    return _sin4_libmvec(x), _cos4_libmvec(x)


# scalar twins: the libm calls the code made before this module, lane by lane
@numba.njit(inline="always", _nrt=False, error_model="numpy")
def _pow4_scalar(x, p):
    return x[0] ** p[0], x[1] ** p[1], x[2] ** p[2], x[3] ** p[3]


@numba.njit(inline="always", _nrt=False, error_model="numpy")
def _exp8_scalar(x):
    return (math.exp(x[0]), math.exp(x[1]), math.exp(x[2]), math.exp(x[3]),
            math.exp(x[4]), math.exp(x[5]), math.exp(x[6]), math.exp(x[7]))


@numba.njit(inline="always", _nrt=False, error_model="numpy")
def _sincos4_scalar(x):
    return ((math.sin(x[0]), math.sin(x[1]), math.sin(x[2]), math.sin(x[3])),
            (math.cos(x[0]), math.cos(x[1]), math.cos(x[2]), math.cos(x[3])))


@numba.njit(inline="always", _nrt=False, error_model="numpy")
def _atanh4_scalar(x):
    return math.atanh(x[0]), math.atanh(x[1]), math.atanh(x[2]), math.atanh(x[3])


if BACKEND == "scalar":
    _pow4, _exp8, _sincos4, _atanh4 = _pow4_scalar, _exp8_scalar, _sincos4_scalar, _atanh4_scalar
else:
    _pow4, _exp8, _sincos4, _atanh4 = _pow4_libmvec, _exp8_libmvec, _sincos4_libmvec, _atanh4_libmvec


@numba.njit(inline="always", _nrt=False, error_model="numpy")
def pow4(x, p):
    """(x_k^p_k for k < 4) of two 4-tuples, within 4 ulp of the exact value (compiled code only)."""
    return _pow4(x, p)


@numba.njit(inline="always", _nrt=False, error_model="numpy")
def exp8(x):
    """(exp(x_k) for k < 8) of an 8-tuple, within 4 ulp of the exact value (compiled code only)."""
    return _exp8(x)


@numba.njit(inline="always", _nrt=False, error_model="numpy")
def sincos4(x):
    """((sin x_k), (cos x_k)) of a 4-tuple, each within 4 ulp of the exact value (compiled code only)."""
    return _sincos4(x)


@numba.njit(inline="always", _nrt=False, error_model="numpy")
def atanh4(x):
    """(atanh x_k) of a 4-tuple, within 4 ulp of the exact value (compiled code only)."""
    return _atanh4(x)
