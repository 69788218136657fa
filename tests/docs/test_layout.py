"""The package layout: no import cycle between packages (function-level imports counted), the
compiled sources are the cache's key, and nothing depends on the speed benchmarks."""
from __future__ import annotations

import ast
from pathlib import Path

import auvtrack
from auvtrack import jit

ROOT = Path(auvtrack.__file__).resolve().parent


def _module_name(path: Path) -> str:
    rel = path.relative_to(ROOT.parent).with_suffix("")
    parts = list(rel.parts)
    if parts[-1] == "__init__":
        parts = parts[:-1]
    return ".".join(parts)


def _imports(path: Path) -> set[str]:
    """Every auvtrack module a file imports, at any depth (module-level and inside functions)."""
    name = _module_name(path)
    package = name if path.name == "__init__.py" else name.rsplit(".", 1)[0]
    out = set()
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        if isinstance(node, ast.Import):
            out |= {a.name for a in node.names if a.name.startswith("auvtrack")}
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")[: len(package.split(".")) - node.level + 1]
                mod = ".".join(base + ([node.module] if node.module else []))
            else:
                mod = node.module or ""
            if mod.startswith("auvtrack"):
                out.add(mod)
                out |= {f"{mod}.{a.name}" for a in node.names}
    return out


def _unit(module: str) -> str:
    """The layout unit of a module: its top-level package or module under auvtrack."""
    parts = module.split(".")
    return parts[1] if len(parts) > 1 else parts[0]


def _graph() -> dict[str, set[str]]:
    units = {p.name if p.is_dir() else p.stem for p in ROOT.iterdir()
             if (p.is_dir() and (p / "__init__.py").exists()) or (p.suffix == ".py" and p.stem != "__init__")}
    graph: dict[str, set[str]] = {u: set() for u in units}
    for path in ROOT.rglob("*.py"):
        src = _unit(_module_name(path))
        if src not in graph:
            continue
        for mod in _imports(path):
            dst = _unit(mod)
            if dst in units and dst != src:
                graph[src].add(dst)
    return graph


def _cycle(graph: dict[str, set[str]]) -> list[str]:
    state: dict[str, int] = {}
    stack: list[str] = []

    def visit(u: str) -> list[str]:
        state[u] = 1
        stack.append(u)
        for v in sorted(graph[u]):
            if state.get(v) == 1:
                return stack[stack.index(v):] + [v]
            if v not in state:
                found = visit(v)
                if found:
                    return found
        stack.pop()
        state[u] = 2
        return []

    for u in sorted(graph):
        if u not in state:
            found = visit(u)
            if found:
                return found
    return []


def test_no_import_cycle_between_packages():
    """Counting imports inside functions too: the package graph is acyclic."""
    cycle = _cycle(_graph())
    assert not cycle, " -> ".join(cycle)


def test_the_cycle_finder_finds_a_cycle():
    assert _cycle({"a": {"b"}, "b": {"c"}, "c": {"a"}}) == ["a", "b", "c", "a"]
    assert _cycle({"a": {"b"}, "b": set()}) == []


def test_nothing_depends_on_the_speed_benchmarks():
    graph = _graph()
    assert [u for u, deps in graph.items() if "perf" in deps and u != "cli"] == []


def test_physics_sits_below_the_engine_and_the_products():
    """The equations (vehicle, plant, environment, reference, control) import neither the engine,
    nor a single run, nor the products built on them."""
    graph = _graph()
    above = {"engine", "simulation", "batch", "studies", "benchmark", "perf", "cli", "scenario", "feasibility"}
    for physics in ("jit", "vehicle", "plant", "environment", "reference", "control", "metrics", "packing", "channels"):
        assert not graph[physics] & above, (physics, graph[physics] & above)


def test_the_kernel_cache_key_covers_every_compiled_source():
    """Every module that defines compiled code, and every auvtrack module it imports, is hashed
    into the kernel cache's name (an edit elsewhere keeps the cache, an edit there never does)."""
    hashed = {p.resolve() for p in jit.compiled_sources()}
    compiled = [p for p in ROOT.rglob("*.py")
                if any(w in p.read_text() for w in ("@njit", "njit(", "@intrinsic", "@kernel_part"))]
    todo, seen = [_module_name(p) for p in compiled], set()
    while todo:
        mod = todo.pop()
        if mod in seen:
            continue
        seen.add(mod)
        path = ROOT.parent / (mod.replace(".", "/") + ".py")
        if not path.exists():
            path = ROOT.parent / mod.replace(".", "/") / "__init__.py"
        if not path.exists():
            continue  # a name imported from a module, not a module
        assert path.resolve() in hashed, f"{mod} feeds compiled code but is not in auvtrack.jit.COMPILED"
        todo += [m for m in _imports(path) if m != "auvtrack"]
