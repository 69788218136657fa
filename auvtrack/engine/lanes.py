"""Lane forms of compiled functions: the same source, L runs at once, branches as masks.

:func:`lane_version` takes a compiled function (a Numba dispatcher: a controller's law, a plant's
``rhs``, the engine's ``stage``, ...) and returns its *lane form*: a function compiled from the
same Python source, rewritten so that every value may be a :class:`auvtrack.jit.lane_values.Lanes` value
(one lane per run) and every branch is taken per lane.  The rewrite is mechanical and keeps each
operation of the source, in order; only control flow changes:

* ``if c: A else: B`` runs A under the mask ``m & c`` and B under ``m & ~c``, each only when
  some lane needs it (a branch no lane takes costs nothing); an assignment in a branch keeps the
  other lanes' value (``x = sel(mask, new, x)``), a store into an array too;
* ``return v`` records v for the lanes of the current mask and retires them; the function
  returns the recorded values (scalars broadcast to lanes);
* ``for i in range(a, b)`` with lane bounds loops over the union of the ranges with each lane
  masked to its own; ``while c`` loops while any lane's c holds; ``break`` / ``continue``
  retire lanes from the loop or the iteration;
* ``a and b``, ``a or b``, ``not a``, chained comparisons and ``x if c else y`` become lane
  operations (both sides evaluated; ``x = a if c else b`` and ``return a if c else b`` become
  branches, so an expensive side runs only for the lanes that need it);
* a call of another compiled function calls its lane form with the current mask.

Arithmetic, comparisons, ``abs``, ``min``, ``max``, ``int``, ``float`` and ``math.*`` work on lanes
as they are (:mod:`auvtrack.jit.lane_values`: each lane gets exactly the scalar operation), so a lane's
result is the scalar function's result for that lane's inputs, bit for bit.  A construct the
rewrite does not handle raises :class:`NotLaneable`; the SIMD back end then falls back to threads.

The lane forms are compiled in memory (they have no file) and inlined by LLVM into their caller,
the engine's :func:`~auvtrack.engine.loop.run_lanes`, whose kernel module is cached on disk.
"""
from __future__ import annotations

import ast
import inspect
import itertools
import linecache
import textwrap
import threading
from typing import Any

import numpy as np
from numba.core.dispatcher import Dispatcher

from ..jit import lane_values as _lanes
from ..jit import njit

__all__ = ["lane_version", "lane_source", "NotLaneable"]

_H = "_LN"  # name of the helper module inside a lane form's globals


class NotLaneable(TypeError):
    """A compiled function uses a construct the lane rewrite does not handle (the message says which)."""


_CACHE: dict[Any, Any] = {}
_SOURCES: dict[Any, str] = {}
_LOCK = threading.RLock()
_IDS = itertools.count()


def _h(name: str, *args: ast.expr) -> ast.Call:
    return ast.Call(func=ast.Attribute(value=ast.Name(id=_H, ctx=ast.Load()), attr=name, ctx=ast.Load()),
                    args=list(args), keywords=[])


def _name(n: str, store: bool = False) -> ast.Name:
    return ast.Name(id=n, ctx=ast.Store() if store else ast.Load())


def _assign(target: str, value: ast.expr) -> ast.Assign:
    return ast.Assign(targets=[_name(target, True)], value=value, lineno=0)


def _contains(nodes, kinds) -> bool:
    for node in nodes:
        for sub in ast.walk(node):
            if isinstance(sub, kinds):
                return True
    return False


def _loop_exits(body) -> bool:
    """Whether a loop body has a break or continue of its own (not of a nested loop)."""
    stack = list(body)
    while stack:
        node = stack.pop()
        if isinstance(node, (ast.Break, ast.Continue)):
            return True
        if isinstance(node, (ast.For, ast.While)):
            continue
        stack.extend(ast.iter_child_nodes(node))
    return False


def _stored_names(s: ast.stmt) -> list[ast.Name]:
    """The Name nodes a statement assigns directly (not in its nested blocks)."""
    targets: list[ast.expr] = []
    if isinstance(s, ast.Assign):
        targets = list(s.targets)
    elif isinstance(s, (ast.For,)):
        targets = [s.target]
    out = []
    for t in targets:
        out += [n for n in ast.walk(t) if isinstance(n, ast.Name) and isinstance(n.ctx, ast.Store)]
    return out


def _block_local_stores(fdef: ast.FunctionDef) -> set[int]:
    """ids of the Name stores whose value is only read later in their own block.

    Such a variable is a temporary of that block: the lanes that do not run the block never read
    the value, so it needs no select (``x = sel(mask, v, x)``) and keeps the type of its value (a
    uniform index stays an integer).  A read elsewhere does not count when an earlier statement of
    its own block (or of an enclosing one that is not around the store) assigns the name first.  A
    store whose statement reads the name, a read before it in its block (a loop-carried value) or
    in a loop header make it non-local.
    """
    chains: dict[int, list] = {}  # id(Name node) -> [(block, index), ...] from the function body down
    loads: dict[str, list] = {}

    def visit(stmts, chain):
        for i, st in enumerate(stmts):
            here = chain + [(stmts, i)]
            for n in ast.walk(st):
                if isinstance(n, ast.Name) and id(n) not in chains:
                    chains[id(n)] = here
            for field in ("body", "orelse"):
                sub = getattr(st, field, None)
                if isinstance(sub, list) and sub and isinstance(sub[0], ast.stmt):
                    for n in (x for s2 in sub for x in ast.walk(s2)):
                        chains.pop(id(n), None)  # re-recorded with the deeper chain
                    visit(sub, here)

    visit(fdef.body, [])
    for n in ast.walk(fdef):
        if isinstance(n, ast.Name) and isinstance(n.ctx, ast.Load):
            loads.setdefault(n.id, []).append(n)

    def covered(x, load_chain, store_chain):
        around = {id(b) for b, _ in store_chain}
        for blk, idx in reversed(load_chain):
            if id(blk) in around:
                return False
            for st in blk[:idx]:
                if any(t.id == x for t in _stored_names(st)):
                    return True
        return False

    local: set[int] = set()

    def check(stmts):
        for i, st in enumerate(stmts):
            own = {n.id for n in ast.walk(st) if isinstance(n, ast.Name) and isinstance(n.ctx, ast.Load)}
            for t in _stored_names(st):
                if t.id in own:
                    continue
                sc = chains[id(t)]
                ok = True
                for ld in loads.get(t.id, ()):
                    lc = chains[id(ld)]
                    after = any(b is stmts and j > i for b, j in lc)
                    if not (after or covered(t.id, lc, sc)):
                        ok = False
                        break
                if ok:
                    local.add(id(t))
            for field in ("body", "orelse"):
                sub = getattr(st, field, None)
                if isinstance(sub, list) and sub and isinstance(sub[0], ast.stmt):
                    check(sub)

    check(fdef.body)
    return local


CHEAP_NODES = 40  # a branch of at most this many AST nodes, without calls, loops or stores, runs unguarded


def _cheap(stmts) -> bool:
    """Whether a block is a few assignments or returns of arithmetic: cheaper to compute for every
    lane and select than to test and branch around (LLVM then has straight-line code)."""
    n = 0
    for s in stmts:
        if not isinstance(s, (ast.Assign, ast.AugAssign, ast.Return, ast.Pass, ast.Expr)):
            return False
        for node in ast.walk(s):
            n += 1
            if isinstance(node, ast.Call) and not (isinstance(node.func, ast.Name) and node.func.id in ("abs",)):
                return False
            if isinstance(node, ast.Subscript) and isinstance(node.ctx, ast.Store):
                return False
            if isinstance(node, ast.BinOp) and isinstance(node.op, (ast.Pow, ast.FloorDiv, ast.Mod)):
                return False  # one scalar call per lane
    return n <= CHEAP_NODES


def _guard(body: list, original) -> list:
    """``if any_lane(_m): body``, or the body itself when the original block is cheap."""
    if _cheap(original):
        return body
    return [ast.If(test=_h("any_lane", _name("_m")), body=body or [ast.Pass()], orelse=[])]


class _Rewriter:
    """Masked form of one function body (see the module docstring)."""

    def __init__(self, fn, scope, resolve):
        self.fn = fn
        self.scope = scope
        self.resolve = resolve  # callable(ast.expr) -> name of a lane form, or None
        self.counter = itertools.count()
        self.returns = False
        self.value_returns = False
        self.first_return = True
        self.loops: list[tuple[str, str, bool]] = []  # (break mask, continue mask, has exits)
        self.defined: set[str] = set()  # names assigned so far, in source order

    def tmp(self, base: str) -> str:
        return f"_{base}{next(self.counter)}"

    # ---------------------------------------------------------------- expressions
    def expr(self, node: ast.expr) -> ast.expr:
        if isinstance(node, ast.BoolOp):
            op = "mask_and" if isinstance(node.op, ast.And) else "mask_or"
            vals = [self.expr(v) for v in node.values]
            out = _h("truth", vals[0])
            for v in vals[1:]:
                out = _h(op, out, _h("truth", v))
            return out
        if isinstance(node, ast.UnaryOp) and isinstance(node.op, ast.Not):
            return _h("mask_not", self.expr(node.operand))
        if isinstance(node, ast.Compare) and len(node.ops) > 1:
            parts = []
            left = node.left
            for op, right in zip(node.ops, node.comparators):
                parts.append(ast.Compare(left=self.expr(left), ops=[op], comparators=[self.expr(right)]))
                left = right
            out = parts[0]
            for p in parts[1:]:
                out = _h("mask_and", out, p)
            return out
        if isinstance(node, ast.IfExp):
            return _h("sel", _h("truth", self.expr(node.test)), self.expr(node.body), self.expr(node.orelse))
        if isinstance(node, ast.BinOp) and isinstance(node.op, ast.Pow):
            # x ** p is one scalar pow per lane: only in the lanes of the mask
            return _h("masked_pow", _name("_m"), self.expr(node.left), self.expr(node.right))
        if isinstance(node, ast.Call):
            target = self.resolve(node.func)
            args = [self.expr(a) for a in node.args]
            if node.keywords:
                raise NotLaneable(f"{self.fn}: keyword arguments in a call are not supported")
            obj = _resolve_attr(node.func, self.scope)
            masked = next((n for n, f in _lanes.MASKED.items() if f is obj and n != "pow"), None)
            if masked is not None:  # an expensive math function: only in the lanes of the mask
                return _h(f"masked_{masked}", _name("_m"), *args)
            if obj is np.zeros or obj is np.empty:  # a per-run work array: one per lane
                if len(args) != 1:
                    raise NotLaneable(f"{self.fn}: np.zeros/np.empty with a dtype is not supported")
                return _h("lane_zeros", args[0], _name("_m"))
            if isinstance(node.func, ast.Attribute) and node.func.attr == "copy" and not args and obj is None:
                return _h("lane_copy", self.expr(node.func.value), _name("_m"))
            if target is not None:
                # a float or boolean constant argument becomes lanes: one compiled form of the callee
                # whether a caller passes a constant or a lane value (integers stay: indices)
                args = [_h("lanes_like", _name("_m"), a) if isinstance(a, ast.Constant) and isinstance(
                    a.value, (bool, float)) else a for a in args]
                return ast.Call(func=_name(target), args=args + [_name("_m")], keywords=[])
            return ast.Call(func=self.expr(node.func), args=args, keywords=[])
        if isinstance(node, (ast.Lambda, ast.ListComp, ast.GeneratorExp, ast.DictComp, ast.SetComp, ast.Await,
                             ast.Yield, ast.YieldFrom, ast.NamedExpr)):
            raise NotLaneable(f"{self.fn}: {type(node).__name__} is not supported")
        for field, value in ast.iter_fields(node):
            if isinstance(value, ast.expr):
                setattr(node, field, self.expr(value))
            elif isinstance(value, list):
                setattr(node, field, [self.expr(v) if isinstance(v, ast.expr) else v for v in value])
        return node

    # ---------------------------------------------------------------- statements
    def mask_after(self, before: str) -> ast.expr:
        """The mask after a construct entered with ``before``: minus retired, broken, continued lanes."""
        m: ast.expr = _name(before)
        if self.returns:
            m = _h("mask_andnot", m, _name("_done"))
        if self.loops and self.loops[-1][2]:
            brk, cont, _ = self.loops[-1]
            m = _h("mask_andnot", _h("mask_andnot", m, _name(brk)), _name(cont))
        return m

    def block(self, stmts, divergent: bool) -> list[ast.stmt]:
        out: list[ast.stmt] = []
        for i, s in enumerate(stmts):
            out += self.stmt(s, divergent)
            rest = stmts[i + 1:]
            if rest and _contains([s], (ast.Return, ast.Break, ast.Continue)):
                # the lanes that left stop here; skip the rest when none is left
                out += _guard(self.block(rest, divergent), rest)
                return out
        return out

    def store(self, target: ast.expr, value: ast.expr, divergent: bool) -> list[ast.stmt]:
        if isinstance(target, ast.Name):
            x = target.id
            known = x in self.defined
            self.defined.add(x)
            if not divergent or id(target) in self.local:
                return [ast.Assign(targets=[_name(x, True)], value=value, lineno=0)]
            if known:
                return [_assign(x, _h("sel", _name("_m"), value, _name(x)))]
            # first definition inside a branch or loop: a typed definition Numba sees first
            # (never taken), so that the select below may read x; the other lanes start at 0
            t = self.tmp("v")
            return [_assign(t, value), ast.If(test=_h("never"), body=[_assign(x, _name(t))], orelse=[]),
                    _assign(x, _h("sel", _name("_m"), _name(t), _name(x)))]
        if isinstance(target, (ast.Tuple, ast.List)):
            t = self.tmp("t")
            out: list[ast.stmt] = [_assign(t, value)]
            for k, elt in enumerate(target.elts):
                if isinstance(elt, ast.Starred):
                    raise NotLaneable(f"{self.fn}: starred assignment is not supported")
                out += self.store(elt, ast.Subscript(value=_name(t), slice=ast.Constant(k), ctx=ast.Load()),
                                  divergent)
            return out
        if isinstance(target, ast.Subscript):
            out, arr, idx = self.subscript_refs(target)
            old = ast.Subscript(value=arr(), slice=idx(), ctx=ast.Load())
            new = _h("sel", _name("_m"), value, old)
            out.append(ast.Assign(targets=[ast.Subscript(value=arr(), slice=idx(), ctx=ast.Store())],
                                  value=new, lineno=0))
            return out
        raise NotLaneable(f"{self.fn}: assignment to {type(target).__name__} is not supported")

    def subscript_refs(self, target: ast.Subscript):
        """(statements, array(), index()) for a store ``a[i] = ...`` that reads ``a[i]`` too.

        A side-effect-free array or index expression is written again where needed (no alias
        variable: in a function with reference counting, a local alias of an array costs two
        atomic updates); anything else is evaluated once into a temporary.
        """
        pre: list[ast.stmt] = []

        def ref(node):
            if _pure(node):
                return lambda: self.expr(_load_copy(node))
            t = self.tmp("x")
            pre.append(_assign(t, self.expr(node)))
            return lambda: _name(t)

        return pre, ref(target.value), ref(target.slice)

    def stmt(self, s: ast.stmt, divergent: bool) -> list[ast.stmt]:
        if isinstance(s, ast.Expr):
            if isinstance(s.value, ast.Constant):  # docstring
                return []
            return [ast.Expr(value=self.expr(s.value))]
        if isinstance(s, ast.Pass):
            return []
        if isinstance(s, ast.Assign):
            if len(s.targets) == 1 and isinstance(s.value, ast.IfExp) and isinstance(s.targets[0], ast.Name):
                # x = a if c else b: a branch, so that each side runs only where needed
                # (fresh target nodes: each branch keeps the other lanes' value, so not block-local)
                t = s.targets[0]
                return self.stmt(ast.If(test=s.value.test,
                                        body=[ast.Assign(targets=[_name(t.id, True)], value=s.value.body, lineno=0)],
                                        orelse=[ast.Assign(targets=[_name(t.id, True)], value=s.value.orelse,
                                                           lineno=0)]), divergent)
            value = self.expr(s.value)
            out: list[ast.stmt] = []
            if len(s.targets) > 1:
                t = self.tmp("v")
                out.append(_assign(t, value))
                value = _name(t)
            for target in s.targets:
                out += self.store(target, value, divergent)
            return out
        if isinstance(s, ast.AugAssign):
            load = _load_copy(s.target)
            value = ast.BinOp(left=load, op=s.op, right=s.value)
            if isinstance(s.target, ast.Subscript):
                # a[i] op= v  ->  a[i] = sel(m, a[i] op v, a[i])
                pre, arr, idx = self.subscript_refs(s.target)
                cur = ast.Subscript(value=arr(), slice=idx(), ctx=ast.Load())
                new = _h("sel", _name("_m"), ast.BinOp(left=cur, op=s.op, right=self.expr(s.value)),
                         ast.Subscript(value=arr(), slice=idx(), ctx=ast.Load()))
                return pre + [ast.Assign(targets=[ast.Subscript(value=arr(), slice=idx(), ctx=ast.Store())],
                                         value=new, lineno=0)]
            return self.store(s.target, self.expr(value), divergent)
        if isinstance(s, ast.If):
            before, cond = self.tmp("mi"), self.tmp("c")
            out = [_assign(before, _name("_m")), _assign(cond, _h("truth", self.expr(s.test))),
                   _assign("_m", _h("mask_and", _name(before), _name(cond))),
                   *_guard(self.block(s.body, True), s.body)]
            if s.orelse:
                out += [_assign("_m", _h("mask_andnot", _name(before), _name(cond))),
                        *_guard(self.block(s.orelse, True), s.orelse)]
            out.append(_assign("_m", self.mask_after(before)))
            return out
        if isinstance(s, ast.Return):
            self.returns = True
            if s.value is not None and isinstance(s.value, ast.IfExp):
                return self.stmt(ast.If(test=s.value.test, body=[ast.Return(value=s.value.body)],
                                        orelse=[ast.Return(value=s.value.orelse)]), divergent)
            out = []
            if s.value is not None:
                self.value_returns = True
                t = self.tmp("r")
                out.append(_assign(t, _h("lanes_like", _name("_m"), self.expr(s.value))))
                if self.first_return:
                    self.first_return = False
                    out.append(ast.If(test=_h("never"), body=[_assign("_rv", _name(t))], orelse=[]))
                out.append(_assign("_rv", _h("sel", _name("_m"), _name(t), _name("_rv"))))
            out += [_assign("_done", _h("mask_or", _name("_done"), _name("_m"))),
                    _assign("_m", _h("no_lanes", _name("_m")))]
            return out
        if isinstance(s, (ast.Break, ast.Continue)):
            if not self.loops:
                raise NotLaneable(f"{self.fn}: break outside a loop")
            brk, cont, _ = self.loops[-1]
            name = brk if isinstance(s, ast.Break) else cont
            return [_assign(name, _h("mask_or", _name(name), _name("_m"))), _assign("_m", _h("no_lanes", _name("_m")))]
        if isinstance(s, ast.For):
            return self.for_loop(s, divergent)
        if isinstance(s, ast.While):
            return self.while_loop(s)
        raise NotLaneable(f"{self.fn}: {type(s).__name__} statements are not supported")

    def uniform(self, e: ast.expr) -> bool:
        """Whether an integer expression is the same for every lane by its form: constants, module
        constants, array shapes, ``len``, and arithmetic, ``min`` or ``max`` of those."""
        if isinstance(e, ast.Constant):
            return isinstance(e.value, int)
        if isinstance(e, (ast.Name, ast.Attribute)):
            if isinstance(e, ast.Name) and e.id in self.assigned:
                return False
            return isinstance(_resolve_attr(e, self.scope), int)
        if isinstance(e, ast.Subscript):
            return (isinstance(e.value, ast.Attribute) and e.value.attr == "shape"
                    and isinstance(e.slice, ast.Constant))
        if isinstance(e, ast.BinOp):
            return self.uniform(e.left) and self.uniform(e.right)
        if isinstance(e, ast.UnaryOp) and isinstance(e.op, ast.USub):
            return self.uniform(e.operand)
        if isinstance(e, ast.Call) and isinstance(e.func, ast.Name) and e.func.id in ("len", "min", "max"):
            return all(self.uniform(a) for a in e.args) and not e.keywords
        return False

    def for_loop(self, s: ast.For, divergent: bool) -> list[ast.stmt]:
        it = s.iter
        if not (isinstance(it, ast.Call) and isinstance(it.func, ast.Name) and it.func.id == "range"
                and 1 <= len(it.args) <= 3 and not it.keywords and isinstance(s.target, ast.Name) and not s.orelse):
            raise NotLaneable(f"{self.fn}: only 'for name in range(...)' loops are supported")
        if (all(self.uniform(a) for a in it.args) and not _loop_exits(s.body)
                and not _contains(s.body, (ast.Return,))):
            # the same iterations for every lane and no way out: a plain loop under the current mask
            self.defined.add(s.target.id)
            self.loops.append(("", "", False))
            body = self.block(s.body, divergent) or [ast.Pass()]
            self.loops.pop()
            return [ast.For(target=_name(s.target.id, True), iter=ast.Call(
                func=_name("range"), args=[self.expr(a) for a in it.args], keywords=[]), body=body, orelse=[],
                lineno=0)]
        args = [self.expr(a) for a in it.args]
        lo, hi, step = (ast.Constant(0), args[0], ast.Constant(1)) if len(args) == 1 else (
            args[0], args[1], args[2] if len(args) == 3 else ast.Constant(1))
        if not (isinstance(step, ast.Constant) and isinstance(step.value, int) and step.value > 0):
            raise NotLaneable(f"{self.fn}: a range step must be a positive integer constant")
        exits = _loop_exits(s.body)
        entry, vlo, vhi = self.tmp("ml"), self.tmp("lo"), self.tmp("hi")
        brk, cont = self.tmp("brk"), self.tmp("cont")
        out: list[ast.stmt] = [_assign(entry, _name("_m")), _assign(vlo, lo), _assign(vhi, hi),
                               _assign(brk, _h("no_lanes", _name("_m")))]
        self.loops.append((brk, cont, exits))
        live: ast.expr = _name(entry)
        if exits:
            live = _h("mask_andnot", live, _name(brk))
        body: list[ast.stmt] = [_assign(cont, _h("no_lanes", _name("_m")))]
        if exits or self.returns or _contains(s.body, (ast.Return,)):
            self.returns = self.returns or _contains(s.body, (ast.Return,))
            if self.returns:
                live = _h("mask_andnot", live, _name("_done"))
            body.append(ast.If(test=_h("mask_not", _h("any_lane", live)), body=[ast.Break()], orelse=[]))
        body.append(_assign("_m", _h("mask_and", live, _h("in_range", _name(s.target.id), _name(vlo), _name(vhi),
                                                         step))))
        body.append(ast.If(test=_h("any_lane", _name("_m")), body=self.block(s.body, True) or [ast.Pass()],
                           orelse=[]))
        self.loops.pop()
        self.defined.add(s.target.id)
        loop = ast.For(target=_name(s.target.id, True),
                       iter=ast.Call(func=_name("range"), args=[_h("lane_min", _name(vlo)), _h("lane_max", _name(vhi)),
                                                                step], keywords=[]),
                       body=body, orelse=[], lineno=0)
        out.append(loop)
        out.append(_assign("_m", self.mask_after(entry)))
        return out

    def while_loop(self, s: ast.While) -> list[ast.stmt]:
        if s.orelse:
            raise NotLaneable(f"{self.fn}: while/else is not supported")
        entry, brk, cont, cond = self.tmp("ml"), self.tmp("brk"), self.tmp("cont"), self.tmp("c")
        out: list[ast.stmt] = [_assign(entry, _name("_m")), _assign(brk, _h("no_lanes", _name("_m")))]
        self.loops.append((brk, cont, True))
        self.returns = self.returns or _contains(s.body, (ast.Return,))
        live: ast.expr = _h("mask_andnot", _name(entry), _name(brk))
        if self.returns:
            live = _h("mask_andnot", live, _name("_done"))
        body: list[ast.stmt] = [
            _assign(cont, _h("no_lanes", _name("_m"))),
            _assign("_m", live),
            ast.If(test=_h("mask_not", _h("any_lane", _name("_m"))), body=[ast.Break()], orelse=[]),
            _assign(cond, _h("truth", self.expr(s.test))),
            _assign(brk, _h("mask_or", _name(brk), _h("mask_andnot", _name("_m"), _name(cond)))),
            _assign("_m", _h("mask_and", _name("_m"), _name(cond))),
            ast.If(test=_h("mask_not", _h("any_lane", _name("_m"))), body=[ast.Break()], orelse=[]),
        ]
        body += self.block(s.body, True)
        self.loops.pop()
        out.append(ast.While(test=ast.Constant(True), body=body, orelse=[]))
        out.append(_assign("_m", self.mask_after(entry)))
        return out

    def function(self, fdef: ast.FunctionDef, name: str) -> ast.FunctionDef:
        a = fdef.args
        if a.vararg or a.kwarg or a.kwonlyargs or a.defaults or a.kw_defaults or a.posonlyargs:
            raise NotLaneable(f"{self.fn}: only plain positional parameters are supported")
        self.returns = _contains(fdef.body, (ast.Return,))
        self.defined = {x.arg for x in a.args}
        self.local = _block_local_stores(fdef)
        self.assigned = {n.id for n in ast.walk(fdef) if isinstance(n, ast.Name) and isinstance(n.ctx, ast.Store)}
        body = self.block(fdef.body, False)
        pre = [_assign("_done", _h("no_lanes", _name("_m")))] if self.returns else []
        post = [ast.Return(value=_name("_rv") if self.value_returns else None)]
        args = ast.arguments(posonlyargs=[], args=list(a.args) + [ast.arg(arg="_m")], vararg=None, kwonlyargs=[],
                             kw_defaults=[], kwarg=None, defaults=[])
        return ast.FunctionDef(name=name, args=args, body=pre + body + post, decorator_list=[], returns=None,
                               type_params=[], lineno=1)


def _stub(disp):
    """The lane form of a procedure the lane kernels never run: the same parameters, does nothing."""
    params = list(inspect.signature(disp.py_func).parameters)
    ns: dict = {"__name__": disp.py_func.__module__}
    exec(f"def {disp.py_func.__name__}__stub({', '.join(params + ['_m'])}):\n    return None\n", ns)  # noqa: S102
    return njit(cache=False, forceinline=True)(ns[f"{disp.py_func.__name__}__stub"])


def _range_params(fdef: ast.FunctionDef) -> list[str]:
    """Parameters that appear in the arguments of a ``range`` (loop bounds, e.g. a number of neurons)."""
    params = {a.arg for a in fdef.args.args}
    found: list[str] = []
    for node in ast.walk(fdef):
        if isinstance(node, ast.Call) and isinstance(node.func, ast.Name) and node.func.id == "range":
            bases = {id(x.value) for a in node.args for x in ast.walk(a) if isinstance(x, (ast.Attribute,
                                                                                           ast.Subscript))}
            for n in (x for a in node.args for x in ast.walk(a)):
                if isinstance(n, ast.Name) and n.id in params and n.id not in found and id(n) not in bases:
                    found.append(n.id)
    return found


def _pure(node: ast.expr) -> bool:
    """An expression without calls (names, constants, attributes, subscripts, arithmetic, tuples)."""
    allowed = (ast.Name, ast.Constant, ast.Attribute, ast.Subscript, ast.BinOp, ast.UnaryOp, ast.Tuple,
               ast.Load, ast.operator, ast.unaryop, ast.Slice)
    return all(isinstance(n, allowed) for n in ast.walk(node))


def _load_copy(target: ast.expr) -> ast.expr:
    node = ast.parse(ast.unparse(target), mode="eval").body
    return node


def _resolve_attr(node: ast.expr, scope: dict):
    """The object an ``a.b.c`` or ``a`` expression names in ``scope`` (None when it is not a global)."""
    parts = []
    while isinstance(node, ast.Attribute):
        parts.append(node.attr)
        node = node.value
    if not isinstance(node, ast.Name) or node.id not in scope:
        return None
    obj = scope[node.id]
    for p in reversed(parts):
        obj = getattr(obj, p, None)
        if obj is None:
            return None
    return obj


def _scope(fn) -> dict:
    scope = dict(fn.__globals__)
    if fn.__closure__:
        scope.update(zip(fn.__code__.co_freevars, (c.cell_contents for c in fn.__closure__)))
    return scope


def lane_source(disp) -> str:
    """The Python source of the lane form of ``disp`` (what :func:`lane_version` compiles; for reading)."""
    lane_version(disp)
    return _SOURCES[disp]


def lane_version(disp):
    """The lane form of a compiled function (see the module docstring), made once per process.

    Parameters
    ----------
    disp : numba dispatcher
        A function compiled with :func:`auvtrack.jit.njit` (or ``numba.njit``).

    Returns
    -------
    numba dispatcher
        ``f(*args, mask)``: the same arguments, each may be lanes or an array of lanes, plus the
        mask of the lanes to compute; returns lanes.

    Raises
    ------
    NotLaneable
        If the source (or a function it calls) uses a construct the rewrite does not handle.
    """
    with _LOCK:
        got = _CACHE.get(disp)
        if got is not None:
            return got
        fn = disp.py_func
        custom = getattr(disp, "lane_form", None)
        if custom is not None:  # a hand-written lane form (e.g. the scalar function once per lane of the mask)
            _CACHE[disp] = custom
            _SOURCES[disp] = f"(hand-written: {custom.py_func.__module__}.{custom.py_func.__qualname__})\n"
            return custom
        if getattr(disp, "lane_stub", False):  # a function the lane kernels never run (the logger)
            out = _stub(disp)
            _CACHE[disp] = out
            _SOURCES[disp] = "(stub: does nothing)\n"
            return out
        scope = _scope(fn)
        callees: dict[str, Any] = {}

        def resolve(node):
            obj = _resolve_attr(node, scope)
            if isinstance(obj, Dispatcher):
                name = f"_lv_{getattr(obj.py_func, '__name__', 'f')}_{id(obj):x}"
                callees[name] = obj
                return name
            return None

        try:
            src = textwrap.dedent(inspect.getsource(fn))
        except (OSError, TypeError) as exc:
            raise NotLaneable(f"{fn.__qualname__}: no source ({exc})") from None
        tree = ast.parse(src)
        fdef = tree.body[0]
        if not isinstance(fdef, ast.FunctionDef):
            raise NotLaneable(f"{fn.__qualname__}: not a plain function")
        name = f"{fn.__name__}__lanes"
        new = _Rewriter(f"{fn.__module__}.{fn.__qualname__}", scope, resolve).function(fdef, name)
        body = [new]
        bounds = _range_params(fdef)
        if bounds:
            # versioning: with every loop-bound parameter the same in all lanes (a run's structure,
            # e.g. the number of neurons), call the copy compiled for it as a plain integer
            uname = name + "_u"
            plain = ast.FunctionDef(name=uname, args=new.args, body=new.body, decorator_list=[], returns=None,
                                    type_params=[], lineno=1)
            test: ast.expr = _h("uniform_int", _name(bounds[0]))
            for b in bounds[1:]:
                test = _h("mask_and", test, _h("uniform_int", _name(b)))
            call = ast.Call(func=_name(uname), args=[_h("lane0", _name(a.arg)) if a.arg in bounds else _name(a.arg)
                                                     for a in new.args.args], keywords=[])
            new = ast.FunctionDef(name=name, args=new.args, body=[ast.If(test=test, body=[ast.Return(value=call)],
                                                                         orelse=[])] + new.body,
                                  decorator_list=[], returns=None, type_params=[], lineno=1)
            body = [plain, new]
        module = ast.Module(body=body, type_ignores=[])
        ast.fix_missing_locations(module)
        text = ast.unparse(module) + "\n"
        filename = f"<lanes {fn.__module__}.{fn.__qualname__} #{next(_IDS)}>"
        linecache.cache[filename] = (len(text), None, text.splitlines(True), filename)
        ns = dict(scope)
        ns[_H] = _lanes
        exec(compile(text, filename, "exec"), ns)  # noqa: S102 - our own rewrite of our own source
        options = {k: v for k, v in disp.targetoptions.items() if k in ("_nrt", "error_model", "fastmath", "nogil")}
        # inlined where the original is (inline="always", or an llvm_inline copy); called elsewhere
        inline = disp.targetoptions.get("inline") == "always" or disp.targetoptions.get("forceinline", False)
        if bounds:
            ns[name + "_u"] = njit(cache=False, forceinline=bool(inline), **options)(ns[name + "_u"])
        out = njit(cache=False, forceinline=bool(inline), **options)(ns[name])
        _CACHE[disp] = out
        _SOURCES[disp] = text
        try:
            for cname, cdisp in callees.items():  # after our own entry: recursion terminates
                ns[cname] = lane_version(cdisp)
        except NotLaneable:  # a callee has no lane form, so neither has this function: not kept
            _CACHE.pop(disp, None)
            _SOURCES.pop(disp, None)
            raise
        return out
