"""Where the compile time of one kernel goes (numba typing, inlining, lowering, LLVM), cold cache.

Usage::

    python benchmarks/compile_profile.py fxtntsmc            # [--plant 5dof] [--lanes] [--top 25] [--json out.json]

Runs in a child process with an empty cache folder (``AUVTRACK_CACHE_DIR`` in a temp dir) and
compiles the (controller, plant) kernel once, recording Numba's compiler events
(``numba.core.event``): every ``numba:compile`` (one per dispatcher specialisation compiled),
every ``numba:run_pass`` (each compiler pass of each function) and every ``numba:llvm_lock``
(time inside LLVM). Times are *exclusive*: a pass that triggers the compilation of a callee
(typing a call compiles the callee) is charged only its own time, the callee's compile is
charged to the callee. Reported: wall time, the sum per pass name, LLVM time, the functions
with the most exclusive time, and how often each function was compiled (specialisations).
Timing on a shared machine is noisy; the shares are what to read.
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

CHILD = r"""
import json, sys, time
from collections import defaultdict
from numba.core import event as ev

import threading
_tls = threading.local()       # per thread: [kind, name, t_start, child_time] and the function compiling
excl = defaultdict(float)      # (kind, name) -> exclusive seconds
count = defaultdict(int)
fn_excl = defaultdict(float)   # function qualname -> exclusive seconds over all its events
fn_llvm = defaultdict(float)   # the part of it inside LLVM
compiles = defaultdict(list)   # qualname -> signatures compiled

def _stack():
    if not hasattr(_tls, "stack"):
        _tls.stack, _tls.fn = [], []
    return _tls.stack, _tls.fn

class L(ev.Listener):
    def on_start(self, e):
        stack, current_fn = _stack()
        name = ""
        if e.kind == "numba:compile":
            d = e.data["dispatcher"]
            name = f"{d.py_func.__module__}.{d.py_func.__qualname__}"
            compiles[name].append(str(e.data["args"]))
            current_fn.append(name)
        elif e.kind == "numba:run_pass":
            name = e.data["name"].split(" [")[0]
        elif e.kind == "numba:llvm_lock":
            name = "llvm"
        stack.append([e.kind, name, time.perf_counter(), 0.0])

    def on_end(self, e):
        stack, current_fn = _stack()
        kind, name, t0, child = stack.pop()
        dt = time.perf_counter() - t0
        if stack:
            stack[-1][3] += dt
        own = dt - child
        key = "llvm" if kind == "numba:llvm_lock" else (name if kind == "numba:run_pass" else "dispatcher")
        excl[key] += own
        count[key] += 1
        if current_fn:
            fn_excl[current_fn[-1]] += own
            if key == "llvm":
                fn_llvm[current_fn[-1]] += own
        if kind == "numba:compile":
            current_fn.pop()

for kind in ("numba:compile", "numba:run_pass", "numba:llvm_lock"):
    ev.register(kind, L())
t0 = time.perf_counter()
from auvtrack.engine import kernels
from auvtrack.control import CONTROLLERS
from auvtrack.plant import PLANTS
t_import = time.perf_counter() - t0
c, p, lanes = sys.argv[1], sys.argv[2], sys.argv[3] == "1"
key = kernels.KernelKey(CONTROLLERS[c].module, PLANTS[p].module, f"{c} on {p}")
if lanes:  # the SIMD batch kernel (its scalar kernel first, not counted)
    from auvtrack.batch.runner import run_batch
    from auvtrack.scenario import load_scenario, paper_scenario_path
    from auvtrack.simulation.pipeline import prepare
    from auvtrack.engine.loop import LANES
    preps = [prepare(load_scenario(paper_scenario_path(), {"controller.kind": c, "sim.duration": 0.01, "seed": i}))
             for i in range(LANES)]  # one full block: fewer runs would go to the single-run kernel
    run_batch(preps, backend="serial")
    for d in (excl, count, fn_excl, fn_llvm, compiles):
        d.clear()
t1, c1 = time.perf_counter(), time.process_time()
if lanes:
    run_batch(preps, backend="simd", workers=1)
else:
    kernels._compile_run(kernels.kernel(key))
wall, cpu = time.perf_counter() - t1, time.process_time() - c1
print(json.dumps({"import_s": t_import, "compile_s": wall, "excl": excl, "count": count, "fn_excl": fn_excl, "fn_llvm": fn_llvm,
                  "compiles": {k: len(v) for k, v in compiles.items()},
                  "signatures": {k: v for k, v in compiles.items() if len(v) > 1}, "cpu_s": cpu}))
"""


def profile(controller: str, plant: str = "5dof", lanes: bool = False) -> dict:
    """Compile one kernel (``lanes``: its SIMD batch kernel) in a child process with an empty cache; return the event totals."""
    with tempfile.TemporaryDirectory() as tmp:
        env = {**os.environ, "AUVTRACK_CACHE_DIR": tmp, "PYTHONPATH": str(Path(__file__).resolve().parents[1])}
        proc = subprocess.run([sys.executable, "-c", CHILD, controller, plant, "1" if lanes else "0"], env=env, cwd=tmp,
                              capture_output=True, text=True)
    if proc.returncode != 0:
        raise SystemExit(f"the compile failed:\n{proc.stderr[-3000:]}")
    return json.loads(proc.stdout.strip().splitlines()[-1])


def main() -> None:
    """Print where one kernel's cold compile time goes."""
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("controller")
    ap.add_argument("--plant", default="5dof")
    ap.add_argument("--lanes", action="store_true", help="the SIMD batch kernel (backend='simd') instead")
    ap.add_argument("--top", type=int, default=25)
    ap.add_argument("--json", type=Path, default=None, help="also write the raw record here")
    args = ap.parse_args()
    load = os.getloadavg()[0]
    doc = profile(args.controller, args.plant, args.lanes)
    doc["load_avg_1min_before"] = load
    if args.json:
        args.json.write_text(json.dumps(doc, indent=1))
    total = doc["compile_s"]
    print(f"{args.controller} on {args.plant}: compile {total:.1f} s wall, {doc['cpu_s']:.1f} s CPU (import {doc['import_s']:.1f} s), "
          f"load {load:.1f}; {sum(doc['compiles'].values())} specialisations of {len(doc['compiles'])} functions")
    for k, v in doc["signatures"].items():
        print(f"  compiled {len(v)}x: {k}")
        for sig in v:
            print(f"      {sig[:300]}")
    print("\nexclusive time by stage")
    for k, v in sorted(doc["excl"].items(), key=lambda kv: -kv[1])[:args.top]:
        print(f"  {v:7.2f} s {100 * v / total:5.1f} %  x{doc['count'][k]:<5d} {k}")
    print("\nexclusive time by function (its typing, lowering and LLVM)")
    for k, v in sorted(doc["fn_excl"].items(), key=lambda kv: -kv[1])[:args.top]:
        print(f"  {v:7.2f} s {100 * v / total:5.1f} %  (LLVM {doc['fn_llvm'].get(k, 0.0):5.2f} s)  "
              f"x{doc['compiles'].get(k, 0):<3d} {k}")


if __name__ == "__main__":
    main()
