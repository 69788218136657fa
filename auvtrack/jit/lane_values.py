"""Lane values for compiled code: L runs side by side in the lanes of one SIMD register.

:class:`Lanes` is a Numba type whose value is an LLVM vector ``<L x double>`` (``<L x i64>``,
``<L x i1>`` for a mask): lane ``l`` belongs to run ``l`` of a batch.  With it the *same* compiled
functions that act on one run's scalars act on L runs (``docs/architecture.md``, "SIMD batch"):

* arithmetic, comparisons, ``abs``, ``min``, ``max``, ``int``, ``float``, ``math.*`` and
  ``**`` accept lanes mixed with scalars (a scalar is broadcast to every lane);
* each lane gets exactly the operation the scalar code does: ``+ - * /``, comparisons, ``abs``
  and selects are vector instructions (IEEE, bit-identical to their scalar forms); everything
  else (``math.exp``, ``x ** p``, ``min``, ``math.floor``...) calls Numba's own scalar
  implementation once per lane, so a lane's value is the scalar code's value bit for bit;
* an array whose dtype is :class:`Lanes` (:func:`as_lanes` of a float64 array with a trailing
  axis of L) holds one value per lane at each index: ``cp[K1]`` loads the gain of every run;
  an index that is itself a lane value gathers (lane l reads its own element).

Control flow that depends on lane values cannot be a Python ``if``: :mod:`auvtrack.engine.lanes`
rewrites a function's branches into masked form with the helpers defined here (:func:`sel`,
:func:`any_lane`, :func:`mask_and` ...).
"""
from __future__ import annotations

import math
import operator

from llvmlite import ir
from numba.core import cgutils, types
from numba.core.imputils import impl_ret_borrowed, lower_builtin, lower_cast
from numba.core.typing.templates import AbstractTemplate, infer_global, signature
from numba.extending import intrinsic, models, register_model
from numba.np.arrayobj import make_array, populate_array

__all__ = ["Lanes", "lanes_of", "as_lanes", "sel", "any_lane", "all_lanes", "no_lanes", "mask_and", "mask_or",
           "mask_not", "mask_andnot", "truth", "lanes_like", "lane_min", "lane_max", "in_range", "get_lane",
           "set_lane", "full_mask", "first_lanes", "never", "lane_zeros", "lane_copy", "lane_column", "lane_at",
           "lane_count"]


class Lanes(types.Type):
    """L values of one scalar type (float64, int64 or boolean), one per lane."""

    def __init__(self, dtype, count: int):
        self.dtype = types.unliteral(dtype)
        self.count = int(count)
        super().__init__(name=f"lanes[{self.dtype}x{self.count}]")

    @property
    def key(self):
        return self.dtype, self.count

    def unify(self, typingctx, other):
        """Lanes with a scalar or other lanes of the same count: lanes of the unified scalar type."""
        other = types.unliteral(other)
        if isinstance(other, Lanes):
            if other.count != self.count:
                return None
            other = other.dtype
        if isinstance(other, (types.Number, types.Boolean)):
            a, b = self.dtype, _scalar_dtype(other)
            if b is None:
                return None
            if a == b:
                return self
            if types.float64 in (a, b):
                return Lanes(types.float64, self.count)
            return Lanes(types.int64, self.count)  # integers and booleans: int64, as every lane index
        return None

    def can_convert_from(self, typingctx, other):
        """A scalar converts to lanes (broadcast); lanes to lanes of a wider type."""
        from numba.core.typeconv import Conversion

        other = types.unliteral(other)
        if isinstance(other, Lanes) and other.count == self.count:
            other = other.dtype
        elif isinstance(other, Lanes):
            return None
        if isinstance(other, (types.Number, types.Boolean)):
            conv = typingctx.can_convert(other, self.dtype)
            if conv is not None:
                return max(conv, Conversion.promote)
        return None


_DTYPES = (types.float64, types.int64, types.boolean)


def _scalar_dtype(t):
    t = types.unliteral(t)
    if isinstance(t, types.Boolean):
        return types.boolean
    if isinstance(t, types.Integer):
        return types.int64
    if isinstance(t, types.Float):
        return types.float64
    return None


def lanes_of(t, count: int):
    """The lane type of ``t``: scalars become :class:`Lanes`, tuples element by element, others unchanged."""
    t = types.unliteral(t)
    if isinstance(t, Lanes):
        return t
    if isinstance(t, types.BaseTuple):
        return types.Tuple([lanes_of(x, count) for x in t.types]) if len(t.types) else t
    dt = _scalar_dtype(t)
    return Lanes(dt, count) if dt is not None else t


@register_model(Lanes)
class _LanesModel(models.PrimitiveModel):
    def __init__(self, dmm, fe_type):
        elt = ir.IntType(1) if fe_type.dtype == types.boolean else dmm.lookup(fe_type.dtype).get_value_type()
        super().__init__(dmm, fe_type, ir.VectorType(elt, fe_type.count))


# ------------------------------------------------------------------ codegen helpers

def _i32(k):
    return ir.Constant(ir.IntType(32), k)


def _splat(context, builder, value, fromty, lanes: Lanes):
    """Broadcast a scalar (cast to the lanes' dtype) or convert lanes to ``lanes``."""
    vty = context.get_value_type(lanes)
    if isinstance(fromty, Lanes):
        if fromty.dtype == lanes.dtype:
            return value
        f, t = fromty.dtype, lanes.dtype
        # the conversions Numba does on a scalar, on all lanes at once
        if f == types.float64 and t == types.int64:
            return builder.fptosi(value, vty)
        if f == types.int64 and t == types.float64:
            return builder.sitofp(value, vty)
        if f == types.boolean and t == types.int64:
            return builder.zext(value, vty)
        if f == types.boolean and t == types.float64:
            return builder.uitofp(value, vty)
        out = ir.Constant(vty, ir.Undefined)
        for k in range(lanes.count):
            x = builder.extract_element(value, _i32(k))
            x = _scalar_cast(context, builder, x, fromty.dtype, lanes.dtype)
            out = builder.insert_element(out, x, _i32(k))
        return out
    x = context.cast(builder, value, fromty, lanes.dtype) if fromty != lanes.dtype else value
    if lanes.dtype == types.boolean:
        x = builder.trunc(x, ir.IntType(1)) if x.type != ir.IntType(1) else x
    out = builder.insert_element(ir.Constant(vty, ir.Undefined), x, _i32(0))
    return builder.shuffle_vector(out, out, ir.Constant(ir.VectorType(ir.IntType(32), lanes.count), [0] * lanes.count))


def _scalar_cast(context, builder, x, fromty, toty):
    if fromty == toty:
        return x
    if fromty == types.boolean:
        # lane booleans are i1 in vectors; Numba's scalar boolean value is i1 as well
        return context.cast(builder, x, types.boolean, toty)
    return context.cast(builder, x, fromty, toty)


def _vcall(builder, base, args, ret):
    """Call the overloaded LLVM intrinsic ``base`` on vector arguments (name mangled by the first one)."""
    vty = args[0].type
    elt = vty.element
    suffix = f"v{vty.count}" + ("f64" if isinstance(elt, ir.DoubleType) else f"i{elt.width}")
    fn = cgutils.get_or_insert_function(builder.module, ir.FunctionType(ret or vty, [a.type for a in args]),
                                        f"{base}.{suffix}")
    return builder.call(fn, args)


def _lane(builder, value, k):
    return builder.extract_element(value, _i32(k) if isinstance(k, int) else k)


@lower_cast(types.Number, Lanes)
@lower_cast(types.Boolean, Lanes)
@lower_cast(Lanes, Lanes)
def _cast_to_lanes(context, builder, fromty, toty, val):
    if isinstance(fromty, Lanes) and fromty.count != toty.count:
        raise TypeError(f"cannot cast {fromty} to {toty}")
    return _splat(context, builder, val, types.unliteral(fromty), toty)


# ------------------------------------------------------------------ lifting scalar functions to lanes

def _count(args):
    counts = {a.count for a in args if isinstance(a, Lanes)}
    if len(counts) != 1:
        return None
    return counts.pop()


def _scalar_args(args):
    return tuple(a.dtype if isinstance(a, Lanes) else types.unliteral(a) for a in args)


def _resolve_scalar(tyctx, fn, args):
    """The scalar signature Numba resolves for ``fn`` on the lanes' dtypes (None if it does not type)."""
    fnty = tyctx.resolve_value_type(fn)
    try:
        sig = tyctx.resolve_function_type(fnty, _scalar_args(args), {})
    except Exception:  # noqa: BLE001 - a typing failure means "not for these types"
        return fnty, None
    return fnty, sig


def _lift_template(fn):
    class LiftLanes(AbstractTemplate):
        key = fn

        def generic(self, args, kws):
            if kws or not any(isinstance(a, Lanes) for a in args):
                return None
            count = _count(args)
            if count is None:
                return None
            if any(not isinstance(a, Lanes) and _scalar_dtype(a) is None for a in args):
                return None
            _, ssig = _resolve_scalar(self.context, fn, args)
            if ssig is None or _scalar_dtype(ssig.return_type) is None:
                return None
            return signature(Lanes(_scalar_dtype(ssig.return_type), count), *args)

    LiftLanes.__name__ = f"LiftLanes_{getattr(fn, '__name__', fn)}"
    return LiftLanes


_FLOAT_VECTOR = {operator.add: "fadd", operator.sub: "fsub", operator.mul: "fmul", operator.truediv: "fdiv",
                 operator.iadd: "fadd", operator.isub: "fsub", operator.imul: "fmul", operator.itruediv: "fdiv"}
_INT_VECTOR = {operator.add: "add", operator.sub: "sub", operator.mul: "mul", operator.iadd: "add",
               operator.isub: "sub", operator.imul: "mul", operator.and_: "and_", operator.or_: "or_",
               operator.xor: "xor", operator.iand: "and_", operator.ior: "or_"}
_CMP = {operator.lt: "<", operator.le: "<=", operator.gt: ">", operator.ge: ">=", operator.eq: "==",
        operator.ne: "!="}


def _lift_lowering(fn):
    def impl(context, builder, sig, args):
        out_ty = sig.return_type
        tyctx = context.typing_context
        fnty, ssig = _resolve_scalar(tyctx, fn, sig.args)
        scal = ssig.args
        # vector fast paths: the same IEEE operation on every lane at once
        if len(args) == 2 and all(s == scal[0] for s in scal):
            st = scal[0]
            vt = Lanes(st, out_ty.count)
            if st == types.float64 and fn in _FLOAT_VECTOR:
                a, b = (_splat(context, builder, v, t, vt) for v, t in zip(args, sig.args))
                return getattr(builder, _FLOAT_VECTOR[fn])(a, b)
            if st == types.int64 and fn in _INT_VECTOR:
                a, b = (_splat(context, builder, v, t, vt) for v, t in zip(args, sig.args))
                return getattr(builder, _INT_VECTOR[fn])(a, b)
            if st == types.boolean and fn in (operator.and_, operator.or_, operator.xor):
                a, b = (_splat(context, builder, v, t, vt) for v, t in zip(args, sig.args))
                return getattr(builder, _INT_VECTOR[fn])(a, b)
            if fn in _CMP and st in (types.float64, types.int64):
                a, b = (_splat(context, builder, v, t, vt) for v, t in zip(args, sig.args))
                op = _CMP[fn]
                if st == types.float64:
                    return builder.fcmp_unordered(op, a, b) if op == "!=" else builder.fcmp_ordered(op, a, b)
                return builder.icmp_signed(op, a, b)
        if fn in (min, max) and len(args) == 2:
            st = _scalar_dtype(tyctx.unify_types(*_scalar_args(sig.args)))
            if st in (types.float64, types.int64) and out_ty.dtype == st:
                vt = Lanes(st, out_ty.count)
                a, b = (_splat(context, builder, v, t, vt) for v, t in zip(args, sig.args))
                op = "<" if fn is min else ">"
                # Numba's do_minmax: acc = a, v = b, v if (v op acc) else acc
                pred = builder.fcmp_ordered(op, b, a) if st == types.float64 else builder.icmp_signed(op, b, a)
                return builder.select(pred, b, a)
        if len(args) == 1 and scal == (types.float64,) and fn in (math.isfinite, math.isnan, math.isinf):
            v = _splat(context, builder, args[0], sig.args[0], Lanes(types.float64, out_ty.count))
            if fn is math.isnan:
                return builder.fcmp_unordered("uno", v, v)
            if fn is math.isfinite:
                d = builder.fsub(v, v)
                return builder.fcmp_ordered("ord", d, d)
            inf = ir.Constant(v.type, [float("inf")] * out_ty.count)
            return builder.or_(builder.fcmp_ordered("==", v, inf), builder.fcmp_ordered("==", v, builder.fneg(inf)))
        if len(args) == 1 and fn in (int, float) and isinstance(sig.args[0], Lanes) and out_ty.dtype in (
                types.int64, types.float64) and sig.args[0].dtype in _DTYPES:
            return _splat(context, builder, args[0], sig.args[0], out_ty)
        if len(args) == 1 and fn in (math.floor, math.ceil) and scal == (types.float64,) and out_ty.dtype == types.int64:
            v = _splat(context, builder, args[0], sig.args[0], Lanes(types.float64, out_ty.count))
            r = _vcall(builder, "llvm.floor" if fn is math.floor else "llvm.ceil", [v], None)
            return builder.fptosi(r, context.get_value_type(out_ty))
        if fn is math.sqrt and scal == (types.float64,):
            v = _splat(context, builder, args[0], sig.args[0], Lanes(types.float64, out_ty.count))
            return _vcall(builder, "llvm.sqrt", [v], None)
        if fn is abs and scal == (types.float64,):
            vt = Lanes(types.float64, out_ty.count)
            a = _splat(context, builder, args[0], sig.args[0], vt)
            return _vcall(builder, "llvm.fabs", [a], None)
        if fn is operator.neg and scal == (types.float64,):
            vt = Lanes(types.float64, out_ty.count)
            return builder.fneg(_splat(context, builder, args[0], sig.args[0], vt))
        # every other function: Numba's scalar implementation, once per lane
        scalar_impl = context.get_function(fnty, ssig)
        star = None  # a *args signature (min, max): the trailing arguments go in one tuple
        if scal and isinstance(scal[-1], (types.StarArgTuple, types.StarArgUniTuple)):
            star = scal[-1]
            scal = tuple(scal[:-1]) + tuple(star.types)
        out = ir.Constant(context.get_value_type(out_ty), ir.Undefined)
        for k in range(out_ty.count):
            vals = []
            for v, t, s in zip(args, sig.args, scal):
                if isinstance(t, Lanes):
                    x = _scalar_cast(context, builder, _lane(builder, v, k), t.dtype, s)
                else:
                    x = context.cast(builder, v, types.unliteral(t), s) if types.unliteral(t) != s else v
                vals.append(x)
            if star is not None:
                n = len(star.types)
                vals = vals[:len(vals) - n] + [context.make_tuple(builder, star, vals[len(vals) - n:])]
            r = scalar_impl(builder, vals)
            r = _scalar_cast(context, builder, r, ssig.return_type, out_ty.dtype)
            if out_ty.dtype == types.boolean and r.type != ir.IntType(1):
                r = builder.trunc(r, ir.IntType(1))
            out = builder.insert_element(out, r, _i32(k))
        return out

    return impl


LIFTED = (
    operator.add, operator.sub, operator.mul, operator.truediv, operator.floordiv, operator.mod, operator.pow,
    operator.iadd, operator.isub, operator.imul, operator.itruediv,
    operator.neg, operator.pos, operator.lt, operator.le, operator.gt, operator.ge, operator.eq, operator.ne,
    operator.and_, operator.or_, operator.xor, operator.lshift, operator.rshift, operator.invert,
    operator.iand, operator.ior,
    abs, min, max, int, float, bool,
    math.exp, math.log, math.log1p, math.expm1, math.sqrt, math.sin, math.cos, math.tan, math.tanh, math.atanh,
    math.atan, math.atan2, math.asin, math.acos, math.sinh, math.cosh, math.floor, math.ceil, math.fabs,
    math.isfinite, math.isnan, math.isinf, math.copysign, math.hypot, math.pow, math.fmod, math.trunc,
)


def _register_lifted():
    for fn in LIFTED:
        infer_global(fn)(_lift_template(fn))
        low = _lift_lowering(fn)
        lower_builtin(fn, Lanes)(low)
        lower_builtin(fn, Lanes, Lanes)(low)
        lower_builtin(fn, Lanes, types.Any)(low)
        lower_builtin(fn, types.Any, Lanes)(low)


_register_lifted()


# ------------------------------------------------------------------ arrays of lanes

@intrinsic
def as_lanes(typingctx, a, count):
    """View a C-contiguous array whose last axis has ``count`` entries as an array of :class:`Lanes`.

    ``as_lanes(x, 4)`` of a float64 array of shape (n, m, 4) is an array of shape (n, m) whose
    elements are lanes of 4; it shares the memory (loads and stores are unaligned vector moves).
    """
    if not isinstance(a, types.Array) or a.layout != "C" or a.ndim < 2 or not isinstance(count, types.IntegerLiteral):
        return None
    L = count.literal_value
    dt = _scalar_dtype(a.dtype)
    if dt is None or dt == types.boolean:
        return None
    ret = types.Array(Lanes(dt, L), a.ndim - 1, "C", aligned=False)

    def codegen(context, builder, sig, args):
        aryty = sig.args[0]
        ary = make_array(aryty)(context, builder, args[0])
        out = make_array(ret)(context, builder)
        shape = cgutils.unpack_tuple(builder, ary.shape)[:-1]
        strides = cgutils.unpack_tuple(builder, ary.strides)[:-1]
        itemsize = context.get_constant(types.intp, context.get_abi_sizeof(context.get_data_type(ret.dtype)))
        data = builder.bitcast(ary.data, context.get_data_type(ret.dtype).as_pointer())
        populate_array(out, data=data, shape=shape, strides=strides, itemsize=itemsize, meminfo=ary.meminfo,
                       parent=ary.parent)
        return impl_ret_borrowed(context, builder, ret, out._getvalue())

    return ret(a, count), codegen


def _is_lane_index(idx):
    if isinstance(idx, Lanes):
        return idx.dtype == types.int64
    if isinstance(idx, types.BaseTuple):
        return any(isinstance(t, Lanes) for t in idx.types) and all(
            isinstance(t, (types.Integer, Lanes)) for t in idx.types)
    return False


class LaneIndex(types.Type):
    """An index tuple with a lane value in it (a gather or scatter: each lane its own element)."""

    def __init__(self, tup):
        self.tup = tup
        super().__init__(name=f"lane_index[{tup}]")

    @property
    def key(self):
        return self.tup


@register_model(LaneIndex)
class _LaneIndexModel(models.ProxyModel):
    def __init__(self, dmm, fe_type):
        super().__init__(dmm, fe_type)
        self._proxied_model = dmm.lookup(fe_type.tup)


@lower_cast(types.BaseTuple, LaneIndex)
def _cast_to_lane_index(context, builder, fromty, toty, val):
    return val


def _lane_index_type(idx):
    return idx if isinstance(idx, Lanes) else LaneIndex(idx)


@infer_global(operator.getitem)
class _GatherTemplate(AbstractTemplate):
    def generic(self, args, kws):
        if len(args) != 2:
            return None
        ary, idx = args
        if isinstance(idx, LaneIndex):  # re-resolved while lowering
            return signature(ary.dtype, ary, idx)
        if not (isinstance(ary, types.Array) and isinstance(ary.dtype, Lanes) and _is_lane_index(idx)):
            return None
        n = len(idx.types) if isinstance(idx, types.BaseTuple) else 1
        if n != ary.ndim:
            return None
        return signature(ary.dtype, ary, _lane_index_type(idx))


def _index_parts(builder, idxty, idx):
    if isinstance(idxty, Lanes):
        return [idx], [idxty]
    return cgutils.unpack_tuple(builder, idx), list(idxty.tup.types)


@lower_builtin(operator.getitem, types.Array, Lanes)
@lower_builtin(operator.getitem, types.Array, LaneIndex)
def _gather(context, builder, sig, args):
    aryty, idxty = sig.args
    lanes = aryty.dtype
    ary = make_array(aryty)(context, builder, args[0])
    base, pos, same = _lane_positions(context, builder, aryty, ary, *_index_parts(builder, idxty, args[1]))
    vty = context.get_value_type(lanes)
    with builder.if_else(same, likely=True) as (uniform, varying):
        with uniform:  # every lane indexes the same element: one vector load
            p0 = builder.bitcast(builder.gep(base, [pos[0]]), vty.as_pointer())
            v_uniform = builder.load(p0, align=8)
            bb_uniform = builder.block
        with varying:
            out = ir.Constant(vty, ir.Undefined)
            for k in range(lanes.count):
                x = builder.load(builder.gep(base, [builder.add(pos[k], context.get_constant(types.intp, k))]))
                out = builder.insert_element(out, x, _i32(k))
            bb_varying = builder.block
    phi = builder.phi(vty)
    phi.add_incoming(v_uniform, bb_uniform)
    phi.add_incoming(out, bb_varying)
    return phi


def _lane_positions(context, builder, aryty, ary, idxs, tys):
    """Element offsets (in scalars, lane 0 of the element) of each lane's index, and whether all are equal.

    The offsets are computed as one integer vector (the row-major flat index of each lane times the
    lane count) and compared with lane 0's in one vector comparison; the per-lane offsets are its
    elements.  Only the address arithmetic is vectorised: every lane loads (or stores) the element
    it indexed before, so the values are unchanged.
    """
    lanes = aryty.dtype
    base = builder.bitcast(ary.data, context.get_value_type(lanes.dtype).as_pointer())
    shape = cgutils.unpack_tuple(builder, ary.shape)
    intp = context.get_value_type(types.intp)
    vty = ir.VectorType(intp, lanes.count)

    def vec(v, t):
        if isinstance(t, Lanes):
            return v if v.type == vty else builder.sext(v, vty)
        return _broadcast(builder, context.cast(builder, v, t, types.intp), vty, lanes.count)

    flat = None
    for i, (v, t) in enumerate(zip(idxs, tys)):
        x = vec(v, t)
        flat = x if flat is None else builder.add(builder.mul(flat, _broadcast(builder, shape[i], vty, lanes.count)), x)
    pos_v = builder.mul(flat, ir.Constant(vty, [lanes.count] * lanes.count))
    first = builder.shuffle_vector(pos_v, pos_v, ir.Constant(ir.VectorType(ir.IntType(32), lanes.count),
                                                             [0] * lanes.count))
    same = _vcall(builder, "llvm.vector.reduce.and", [builder.icmp_signed("==", pos_v, first)], ir.IntType(1))
    pos = [builder.extract_element(pos_v, _i32(k)) for k in range(lanes.count)]
    return base, pos, same


@intrinsic
def lane_column(typingctx, a, k):
    """Lane ``k`` of a 1-D array of :class:`Lanes`: a float64 (or int64) array view of that lane's
    elements, strided over the others (loads and stores go to the array of lanes itself)."""
    if not (isinstance(a, types.Array) and isinstance(a.dtype, Lanes) and a.ndim == 1
            and isinstance(k, types.Integer)):
        return None
    ret = types.Array(a.dtype.dtype, 1, "A")

    def codegen(context, builder, sig, args):
        ary = make_array(a)(context, builder, args[0])
        out = make_array(ret)(context, builder)
        base = builder.bitcast(ary.data, context.get_data_type(ret.dtype).as_pointer())
        data = builder.gep(base, [context.cast(builder, args[1], sig.args[1], types.intp)])
        itemsize = context.get_constant(types.intp, context.get_abi_sizeof(context.get_data_type(ret.dtype)))
        populate_array(out, data=data, shape=ary.shape, strides=ary.strides, itemsize=itemsize,
                       meminfo=ary.meminfo, parent=ary.parent)
        return impl_ret_borrowed(context, builder, ret, out._getvalue())

    return ret(a, k), codegen


@intrinsic
def lane_at(typingctx, x, k):
    """Lane ``k`` of a lane value as a scalar; a scalar (the same in every lane) as it is."""
    if not isinstance(k, types.Integer):
        return None
    if isinstance(x, Lanes):
        def codegen(context, builder, sig, args):
            return builder.extract_element(args[0], context.cast(builder, args[1], sig.args[1], types.int32))

        return x.dtype(x, k), codegen
    if _scalar_dtype(x) is None:
        return None
    return types.unliteral(x)(x, k), lambda context, builder, sig, args: args[0]


@intrinsic
def lane_count(typingctx, m):
    """The number of lanes of a lane value (a compile-time constant)."""
    if not isinstance(m, Lanes):
        return None
    return types.intp(m), lambda context, builder, sig, args: context.get_constant(types.intp, m.count)

# ------------------------------------------------------------------ masks and selects

def _mask_count(*tys):
    counts = {t.count for t in tys if isinstance(t, Lanes)}
    return counts.pop() if len(counts) == 1 else None


def _is_maskish(t):
    t = types.unliteral(t)
    return isinstance(t, types.Boolean) or (isinstance(t, Lanes) and t.dtype == types.boolean)


def _as_mask(context, builder, v, t, count):
    return _splat(context, builder, v, types.unliteral(t), Lanes(types.boolean, count))


def _mask_binop(name):
    @intrinsic
    def fn(typingctx, a, b):
        if not (_is_maskish(a) and _is_maskish(b)):
            return None
        count = _mask_count(a, b)
        if count is None:
            ret = types.boolean

            def codegen_scalar(context, builder, sig, args):
                x, y = args
                if name == "and":
                    return builder.and_(x, y)
                if name == "or":
                    return builder.or_(x, y)
                return builder.and_(x, builder.not_(y))

            return ret(a, b), codegen_scalar
        ret = Lanes(types.boolean, count)

        def codegen(context, builder, sig, args):
            x = _as_mask(context, builder, args[0], sig.args[0], count)
            y = _as_mask(context, builder, args[1], sig.args[1], count)
            if name == "and":
                return builder.and_(x, y)
            if name == "or":
                return builder.or_(x, y)
            return builder.and_(x, builder.not_(y))

        return ret(a, b), codegen

    return fn


mask_and = _mask_binop("and")
mask_or = _mask_binop("or")
mask_andnot = _mask_binop("andnot")
mask_and.__doc__ = "a and b, lane by lane (both evaluated; scalars broadcast)."
mask_or.__doc__ = "a or b, lane by lane (both evaluated)."
mask_andnot.__doc__ = "a and not b, lane by lane."


@intrinsic
def truth(typingctx, a):
    """Truth value of ``a`` as a boolean or a lane mask (``!= 0`` for numbers)."""
    a = types.unliteral(a)
    if isinstance(a, Lanes):
        ret = Lanes(types.boolean, a.count)

        def codegen(context, builder, sig, args):
            v = args[0]
            if a.dtype == types.boolean:
                return v
            zero = ir.Constant(v.type, None)
            if a.dtype == types.float64:
                return builder.fcmp_unordered("!=", v, zero)
            return builder.icmp_signed("!=", v, zero)

        return ret(a), codegen
    if isinstance(a, (types.Boolean, types.Number)):
        def codegen_s(context, builder, sig, args):
            return context.is_true(builder, sig.args[0], args[0])

        return types.boolean(a), codegen_s
    return None


@intrinsic
def mask_not(typingctx, a):
    """not a, lane by lane (truth value first)."""
    a = types.unliteral(a)
    if isinstance(a, Lanes):
        ret = Lanes(types.boolean, a.count)

        def codegen(context, builder, sig, args):
            v = args[0]
            if a.dtype == types.boolean:
                return builder.not_(v)
            zero = ir.Constant(v.type, None)
            if a.dtype == types.float64:
                return builder.fcmp_ordered("==", v, zero)
            return builder.icmp_signed("==", v, zero)

        return ret(a), codegen
    if isinstance(a, (types.Boolean, types.Number)):
        def codegen_s(context, builder, sig, args):
            return builder.not_(context.is_true(builder, sig.args[0], args[0]))

        return types.boolean(a), codegen_s
    return None


def _reduce(name):
    @intrinsic
    def fn(typingctx, m):
        m = types.unliteral(m)
        if isinstance(m, types.Boolean):
            return types.boolean(m), lambda context, builder, sig, args: args[0]
        if not (isinstance(m, Lanes) and m.dtype == types.boolean):
            return None

        def codegen(context, builder, sig, args):
            return _vcall(builder, f"llvm.vector.reduce.{name}", [args[0]], ir.IntType(1))

        return types.boolean(m), codegen

    return fn


any_lane = _reduce("or")
all_lanes = _reduce("and")
any_lane.__doc__ = "True when any lane of the mask is set (a boolean is itself)."
all_lanes.__doc__ = "True when every lane of the mask is set."


@intrinsic
def no_lanes(typingctx, m):
    """The all-false mask of the same type as ``m``."""
    m = types.unliteral(m)
    if isinstance(m, Lanes) and m.dtype == types.boolean:
        return m(m), lambda context, builder, sig, args: ir.Constant(args[0].type, None)
    if isinstance(m, types.Boolean):
        return types.boolean(m), lambda context, builder, sig, args: ir.Constant(ir.IntType(1), 0)
    return None


def _sel_type(count, a, b):
    a, b = types.unliteral(a), types.unliteral(b)
    if isinstance(a, types.BaseTuple) or isinstance(b, types.BaseTuple):
        if not (isinstance(a, types.BaseTuple) and isinstance(b, types.BaseTuple)) or len(a) != len(b):
            return None
        parts = [_sel_type(count, x, y) for x, y in zip(a.types, b.types)]
        return None if any(p is None for p in parts) else types.Tuple(parts)
    if isinstance(a, types.NoneType) and isinstance(b, types.NoneType):
        return a
    if count is None:  # everything uniform: a scalar select
        da, db = _scalar_dtype(a), _scalar_dtype(b)
        if da is None or db is None:
            return None
        if da == db:
            return da
        return types.float64 if types.float64 in (da, db) else types.int64
    la, lb = lanes_of(a, count), lanes_of(b, count)
    if not (isinstance(la, Lanes) and isinstance(lb, Lanes)):
        return None
    if la.dtype == lb.dtype:
        return la
    dt = types.float64 if types.float64 in (la.dtype, lb.dtype) else types.int64
    return Lanes(dt, count)


def _sel_codegen(context, builder, mask, ta, a, tb, b, tr):
    if isinstance(tr, types.BaseTuple):
        items = []
        for i, t in enumerate(tr.types):
            xa = builder.extract_value(a, i)
            xb = builder.extract_value(b, i)
            items.append(_sel_codegen(context, builder, mask, ta.types[i], xa, tb.types[i], xb, t))
        return context.make_tuple(builder, tr, items)
    if isinstance(tr, types.NoneType):
        return a
    if not isinstance(tr, Lanes):
        va = context.cast(builder, a, types.unliteral(ta), tr)
        vb = context.cast(builder, b, types.unliteral(tb), tr)
        return builder.select(mask, va, vb)
    va = _splat(context, builder, a, types.unliteral(ta), tr)
    vb = _splat(context, builder, b, types.unliteral(tb), tr)
    return builder.select(mask, va, vb)


@intrinsic
def sel(typingctx, m, a, b):
    """Lane by lane ``a if m else b`` (``m`` a mask or a boolean; tuples element by element; result in lanes)."""
    m = types.unliteral(m)
    if isinstance(m, Lanes) and m.dtype == types.boolean:
        count = m.count
    elif isinstance(m, types.Boolean):
        count = _first_count(a) or _first_count(b)
    else:
        return None
    ret = _sel_type(count, a, b)
    if ret is None:
        return None

    def codegen(context, builder, sig, args):
        if count is None:
            mask = context.is_true(builder, sig.args[0], args[0])
        else:
            mask = _as_mask(context, builder, args[0], sig.args[0], count)
        return _sel_codegen(context, builder, mask, sig.args[1], args[1], sig.args[2], args[2], sig.return_type)

    return ret(m, a, b), codegen


def _first_count(t):
    t = types.unliteral(t)
    if isinstance(t, Lanes):
        return t.count
    if isinstance(t, types.BaseTuple):
        for x in t.types:
            c = _first_count(x)
            if c is not None:
                return c
    return None


def _lanes_codegen(context, builder, t, v, tr):
    if isinstance(tr, types.BaseTuple):
        return context.make_tuple(builder, tr, [_lanes_codegen(context, builder, t.types[i], builder.extract_value(v, i),
                                                               x) for i, x in enumerate(tr.types)])
    if isinstance(tr, Lanes):
        return _splat(context, builder, v, types.unliteral(t), tr)
    return v


@intrinsic
def lanes_like(typingctx, m, a):
    """``a`` with every scalar broadcast to the lanes of the mask ``m`` (tuples element by element)."""
    m = types.unliteral(m)
    if not (isinstance(m, Lanes) and m.dtype == types.boolean):
        return None
    ret = lanes_of(a, m.count)

    def codegen(context, builder, sig, args):
        return _lanes_codegen(context, builder, sig.args[1], args[1], sig.return_type)

    return ret(m, a), codegen


def _extreme(name):
    @intrinsic
    def fn(typingctx, x):
        x = types.unliteral(x)
        if isinstance(x, types.Integer):
            return types.int64(x), lambda context, builder, sig, args: context.cast(builder, args[0], sig.args[0],
                                                                                     types.int64)
        if not (isinstance(x, Lanes) and x.dtype == types.int64):
            return None

        def codegen(context, builder, sig, args):
            return _vcall(builder, f"llvm.vector.reduce.{name}", [args[0]], ir.IntType(64))

        return types.int64(x), codegen

    return fn


lane_min = _extreme("smin")
lane_max = _extreme("smax")
lane_min.__doc__ = "The smallest lane of an integer lane value (an integer is itself): a loop's first index."
lane_max.__doc__ = "The largest lane of an integer lane value: a loop's last bound."


@intrinsic
def in_range(typingctx, i, lo, hi, step):
    """Mask of the lanes for which the loop index ``i`` is in ``range(lo, hi, step)`` (True for scalar bounds)."""
    tys = [types.unliteral(t) for t in (lo, hi, step)]
    count = _mask_count(*tys)
    if count is None:
        if all(isinstance(t, types.Integer) for t in tys):
            return types.boolean(i, lo, hi, step), lambda context, builder, sig, args: ir.Constant(ir.IntType(1), 1)
        return None
    ret = Lanes(types.boolean, count)
    vt = Lanes(types.int64, count)

    def codegen(context, builder, sig, args):
        iv, lv, hv, sv = (_splat(context, builder, v, types.unliteral(t), vt) for v, t in zip(args, sig.args))
        pos = builder.icmp_signed(">", sv, ir.Constant(sv.type, None))
        up = builder.and_(builder.icmp_signed(">=", iv, lv), builder.icmp_signed("<", iv, hv))
        down = builder.and_(builder.icmp_signed("<=", iv, lv), builder.icmp_signed(">", iv, hv))
        # on the index grid lo + n step
        off = builder.sub(iv, lv)
        on = builder.icmp_signed("==", builder.srem(off, sv), ir.Constant(sv.type, None))
        return builder.and_(builder.select(pos, up, down), on)

    return ret(i, lo, hi, step), codegen


@intrinsic
def get_lane(typingctx, v, k):
    """Lane ``k`` of a lane value, as a scalar."""
    if not isinstance(v, Lanes) or not isinstance(k, types.Integer):
        return None

    def codegen(context, builder, sig, args):
        x = builder.extract_element(args[0], context.cast(builder, args[1], sig.args[1], types.int32))
        return x

    return v.dtype(v, k), codegen


@intrinsic
def set_lane(typingctx, v, k, x):
    """``v`` with lane ``k`` replaced by the scalar ``x``."""
    if not isinstance(v, Lanes) or not isinstance(k, types.Integer):
        return None

    def codegen(context, builder, sig, args):
        s = context.cast(builder, args[2], sig.args[2], v.dtype)
        if v.dtype == types.boolean and s.type != ir.IntType(1):
            s = builder.trunc(s, ir.IntType(1))
        return builder.insert_element(args[0], s, context.cast(builder, args[1], sig.args[1], types.int32))

    return v(v, k, x), codegen


@intrinsic
def full_mask(typingctx, count):
    """The all-true mask of ``count`` lanes (a literal integer)."""
    if not isinstance(count, types.IntegerLiteral):
        return None
    ret = Lanes(types.boolean, count.literal_value)

    def codegen(context, builder, sig, args):
        return ir.Constant(context.get_value_type(ret), [1] * ret.count)

    return ret(count), codegen


@intrinsic
def never(typingctx):
    """False, opaque to Numba's branch pruning (LLVM folds it): gives a variable a typed first definition."""
    return types.boolean(), lambda context, builder, sig, args: ir.Constant(ir.IntType(1), 0)


# ------------------------------------------------------------------ scatter (store at lane indices)

@infer_global(operator.setitem)
class _ScatterTemplate(AbstractTemplate):
    def generic(self, args, kws):
        if len(args) != 3:
            return None
        ary, idx, val = args
        if isinstance(idx, LaneIndex):
            return signature(types.none, ary, idx, ary.dtype)
        if not (isinstance(ary, types.Array) and isinstance(ary.dtype, Lanes) and _is_lane_index(idx)):
            return None
        n = len(idx.types) if isinstance(idx, types.BaseTuple) else 1
        if n != ary.ndim:
            return None
        return signature(types.none, ary, _lane_index_type(idx), ary.dtype)


@lower_builtin(operator.setitem, types.Array, Lanes, types.Any)
@lower_builtin(operator.setitem, types.Array, LaneIndex, types.Any)
def _scatter(context, builder, sig, args):
    aryty, idxty, valty = sig.args
    lanes = aryty.dtype
    val = _splat(context, builder, args[2], types.unliteral(valty), lanes)
    ary = make_array(aryty)(context, builder, args[0])
    base, pos, same = _lane_positions(context, builder, aryty, ary, *_index_parts(builder, idxty, args[1]))
    with builder.if_else(same, likely=True) as (uniform, varying):
        with uniform:  # one element for every lane: one vector store
            builder.store(val, builder.bitcast(builder.gep(base, [pos[0]]), val.type.as_pointer()), align=8)
        with varying:
            for k in range(lanes.count):
                builder.store(_lane(builder, val, k),
                              builder.gep(base, [builder.add(pos[k], context.get_constant(types.intp, k))]))
    return context.get_dummy_value()


# ------------------------------------------------------------------ allocation in lane forms

def lane_zeros(shape, m):
    """Zeros of ``shape`` (an int, lanes of ints or a tuple of ints), one per lane of the mask ``m``.

    Compiled code only: an array of float64 :class:`Lanes`; a lane-valued size uses the largest lane.
    """
    raise NotImplementedError("compiled code only")


def lane_copy(a, m):
    """A copy of an array of lanes (compiled code only)."""
    raise NotImplementedError("compiled code only")


def _register_allocation():
    import numpy as np
    from numba.extending import overload

    @overload(lane_zeros)
    def _ol_zeros(shape, m):
        if not (isinstance(m, Lanes) and m.dtype == types.boolean):
            return None
        L = m.count
        if isinstance(shape, (types.Integer, Lanes)):
            def impl(shape, m):
                return as_lanes(np.zeros((lane_max(shape), L)), L)
            return impl
        if isinstance(shape, types.BaseTuple) and len(shape) == 2:
            def impl2(shape, m):
                return as_lanes(np.zeros((lane_max(shape[0]), lane_max(shape[1]), L)), L)
            return impl2
        return None

    @overload(lane_copy)
    def _ol_copy(a, m):
        if not (isinstance(a, types.Array) and isinstance(a.dtype, Lanes)):
            return None
        L = a.dtype.count
        dt = np.float64 if a.dtype.dtype == types.float64 else np.int64
        if a.ndim == 1:
            def impl(a, m):
                out = np.empty((a.shape[0], L), dt)
                v = as_lanes(out, L)
                for i in range(a.shape[0]):
                    v[i] = a[i]
                return v
            return impl
        return None


_register_allocation()


@intrinsic
def first_lanes(typingctx, n, count):
    """The mask of lanes ``0 .. n - 1`` out of ``count`` (a literal integer)."""
    if not (isinstance(count, types.IntegerLiteral) and isinstance(n, types.Integer)):
        return None
    L = count.literal_value
    ret = Lanes(types.boolean, L)

    def codegen(context, builder, sig, args):
        nv = context.cast(builder, args[0], sig.args[0], types.int64)
        vt = ir.VectorType(ir.IntType(64), L)
        iota = ir.Constant(vt, list(range(L)))
        return builder.icmp_signed("<", iota, _splat(context, builder, nv, types.int64, Lanes(types.int64, L)))

    return ret(n, count), codegen


@intrinsic
def uniform_int(typingctx, x):
    """True when every lane of an integer lane value is equal (an integer is uniform)."""
    x = types.unliteral(x)
    if not (isinstance(x, Lanes) and x.dtype == types.int64):  # anything but integer lanes is uniform
        return types.boolean(x), lambda context, builder, sig, args: ir.Constant(ir.IntType(1), 1)

    def codegen(context, builder, sig, args):
        v = args[0]
        first = builder.extract_element(v, _i32(0))
        eq = builder.icmp_signed("==", v, _splat(context, builder, first, types.int64, x))
        return _vcall(builder, "llvm.vector.reduce.and", [eq], ir.IntType(1))

    return types.boolean(x), codegen


@intrinsic
def lane0(typingctx, x):
    """Lane 0 of an integer lane value as an integer (anything else is returned as it is)."""
    if not (isinstance(x, Lanes) and x.dtype == types.int64):
        return x(x), lambda context, builder, sig, args: args[0]
    return types.int64(x), lambda context, builder, sig, args: builder.extract_element(args[0], _i32(0))


# ------------------------------------------------------------------ masked scalar calls

MASKED = {"pow": operator.pow, "exp": math.exp, "log": math.log, "log1p": math.log1p, "expm1": math.expm1,
          "sin": math.sin, "cos": math.cos, "tan": math.tan, "tanh": math.tanh, "atanh": math.atanh,
          "atan": math.atan, "atan2": math.atan2, "asin": math.asin, "acos": math.acos, "sinh": math.sinh,
          "cosh": math.cosh, "hypot": math.hypot, "fmod": math.fmod}
"""The expensive scalar functions a lane form evaluates only in the lanes of its mask (``**`` and ``math.*``)."""


def _masked_typing(fn, typingctx, m, args):
    m = types.unliteral(m)
    if not any(isinstance(a, Lanes) for a in args):  # uniform: the plain scalar function
        fnty, ssig = _resolve_scalar(typingctx, fn, args)
        if ssig is None:
            return None

        def codegen_s(context, builder, sig, cargs):
            vals = [context.cast(builder, v, types.unliteral(t), s) for v, t, s in zip(cargs[1:], args, ssig.args)]
            return context.get_function(fnty, ssig)(builder, vals)

        return signature(ssig.return_type, m, *args), codegen_s
    if not (isinstance(m, Lanes) and m.dtype == types.boolean):
        return None
    count = _count(args)
    fnty, ssig = _resolve_scalar(typingctx, fn, args)
    if count is None or count != m.count or ssig is None or _scalar_dtype(ssig.return_type) is None:
        return None
    ret = Lanes(_scalar_dtype(ssig.return_type), count)

    def codegen(context, builder, sig, cargs):
        mask, vals = cargs[0], cargs[1:]
        impl = context.get_function(fnty, ssig)

        def lane_args(k):
            return [_scalar_cast(context, builder, _lane(builder, v, k), t.dtype, s) if isinstance(t, Lanes)
                    else context.cast(builder, v, types.unliteral(t), s) for v, t, s in zip(vals, args, ssig.args)]

        vty = context.get_value_type(ret)
        first = _first_lane(builder, mask, count)
        with builder.if_else(_same_in_active_lanes(builder, mask, first, vals, args)) as (uniform, varied):
            with uniform:  # one call for every lane (a time or parameter shared by the runs of a block)
                r = _scalar_cast(context, builder, impl(builder, lane_args(first)), ssig.return_type, ret.dtype)
                one = _broadcast(builder, r, vty, count)
                bb_one = builder.block
            with varied:
                every = _vcall(builder, "llvm.vector.reduce.and", [mask], ir.IntType(1))
                with builder.if_else(every, likely=True) as (all_on, some_off):
                    with all_on:  # every lane, without a branch per lane
                        full = ir.Constant(vty, ir.Undefined)
                        for k in range(count):
                            r = _scalar_cast(context, builder, impl(builder, lane_args(k)), ssig.return_type,
                                             ret.dtype)
                            full = builder.insert_element(full, r, _i32(k))
                        bb_full = builder.block
                    with some_off:
                        part = _masked_lanes(context, builder, impl, mask, lane_args, ssig, ret, count)
                        bb_part = builder.block
                each = builder.phi(vty)
                each.add_incoming(full, bb_full)
                each.add_incoming(part, bb_part)
                bb_each = builder.block
        phi = builder.phi(vty)
        phi.add_incoming(one, bb_one)
        phi.add_incoming(each, bb_each)
        return phi

    return signature(ret, m, *args), codegen


def _first_lane(builder, mask, count: int):
    """i32 index of the first lane of ``mask`` (0 when the mask is empty)."""
    bits = builder.zext(builder.bitcast(mask, ir.IntType(count)), ir.IntType(32))
    fn = cgutils.get_or_insert_function(builder.module, ir.FunctionType(ir.IntType(32), [ir.IntType(32), ir.IntType(1)]),
                                        "llvm.cttz.i32")
    k = builder.call(fn, [builder.or_(bits, _i32(1 << count)), ir.Constant(ir.IntType(1), 0)])
    return builder.select(builder.icmp_unsigned("<", k, _i32(count)), k, _i32(0))


def _broadcast(builder, x, vty, count: int):
    """The scalar ``x`` in every lane of a vector of type ``vty``."""
    one = builder.insert_element(ir.Constant(vty, ir.Undefined), x, _i32(0))
    return builder.shuffle_vector(one, one, ir.Constant(ir.VectorType(ir.IntType(32), count), [0] * count))


def _same_in_active_lanes(builder, mask, first, vals, args):
    """i1: in every lane of ``mask`` each lane argument has the bits it has in lane ``first`` (scalars
    are the same in every lane by nature).  Then a function of the arguments is called once for all
    of them: bit for bit each lane's own result."""
    same = ir.Constant(ir.IntType(1), 1)
    for v, t in zip(vals, args):
        if not isinstance(t, Lanes):
            continue
        if isinstance(v.type.element, ir.DoubleType):
            v = builder.bitcast(v, ir.VectorType(ir.IntType(64), t.count))
        ref = _broadcast(builder, builder.extract_element(v, first), v.type, t.count)
        eq = builder.icmp_unsigned("==", builder.select(mask, v, ref), ref)
        same = builder.and_(same, _vcall(builder, "llvm.vector.reduce.and", [eq], ir.IntType(1)))
    return same


def _same_in_every_lane(builder, vals, count: int):
    """i1: each of the float64 lane vectors ``vals`` holds lane 0's bits in all ``count`` lanes."""
    full = ir.Constant(ir.VectorType(ir.IntType(1), count), [1] * count)
    return _same_in_active_lanes(builder, full, _i32(0), vals, [Lanes(types.float64, count)] * len(vals))


def _masked_lanes(context, builder, impl, mask, lane_args, ssig, ret, count):
    """Per lane: the scalar function where the mask is set, 0 elsewhere."""
    out = ir.Constant(context.get_value_type(ret), ir.Undefined)
    for k in range(count):
        on = builder.extract_element(mask, _i32(k))
        with builder.if_else(on) as (then, otherwise):
            with then:
                r = _scalar_cast(context, builder, impl(builder, lane_args(k)), ssig.return_type, ret.dtype)
                bb_then = builder.block
            with otherwise:
                bb_else = builder.block
        phi = builder.phi(r.type)
        phi.add_incoming(r, bb_then)
        phi.add_incoming(ir.Constant(r.type, None), bb_else)
        out = builder.insert_element(out, phi, _i32(k))
    return out


def _masked(fn, nargs: int):
    if nargs == 1:
        @intrinsic
        def call(typingctx, m, x):
            return _masked_typing(fn, typingctx, m, (x,))
    else:
        @intrinsic
        def call(typingctx, m, x, y):
            return _masked_typing(fn, typingctx, m, (x, y))
    call.__doc__ = (f"``{getattr(fn, '__name__', fn)}`` of the arguments in the lanes of the mask only (once when "
                    "their arguments have the same bits); the other lanes' values are unspecified.")
    return call


_BINARY = ("pow", "atan2", "hypot", "fmod")
masked_calls = {name: _masked(fn, 2 if name in _BINARY else 1) for name, fn in MASKED.items()}
globals().update({f"masked_{name}": f for name, f in masked_calls.items()})
