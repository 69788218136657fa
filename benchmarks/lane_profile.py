"""Where the SIMD lane kernel's time goes: ``perf record`` of SIMD batches, the kernel's own functions named.

Usage (Linux with ``perf``)::

    python benchmarks/lane_profile.py                  # [--controller fxtntsmc] [--seconds 15]

One child process prepares 16 runs of the 10 s Section 4 scenario, runs them once with
``run_batch(backend="simd", workers=1)`` (compile or load), writes ``/tmp/perf-<pid>.map`` naming
the functions of its lane kernel (read from the kernel's cached object code), then repeats the batch
for ``--seconds`` under ``perf record -e cpu-clock``.  Printed: the share of samples per function
(the lane kernel's own parts, libmvec and libm calls, Python), which is how benchmarks/profile.md
("SIMD session 2") split the lane kernel's time.  The set-up before the loop is in the samples too
(the Python rows); compilation is not: a first child run compiles or loads the kernels.
"""
from __future__ import annotations

import argparse
import os
import re
import struct
import subprocess
import sys
import tempfile
import time
from pathlib import Path


def _object_code(nbc: Path) -> bytes:
    """The ELF object inside a Numba cache entry (the machine code of the kernel's library)."""
    data = nbc.read_bytes()
    i = data.find(b"\x7fELF")
    shoff, = struct.unpack_from("<Q", data, i + 0x28)
    shentsize, shnum = struct.unpack_from("<HH", data, i + 0x3A)
    return data[i:i + shoff + shentsize * shnum]


def _demangle(symbol: str) -> str:
    """``a.b.name`` from a Numba symbol ``_ZN<len>a<len>b<len>nameB...`` (the part before its type signature)."""
    if not symbol.startswith("_ZN"):
        return symbol
    parts, i = [], 3
    while i < len(symbol) and symbol[i].isdigit():
        j = i
        while symbol[j].isdigit():
            j += 1
        parts.append(symbol[j:j + int(symbol[i:j])])
        i = j + int(symbol[i:j])
    return ".".join(parts) or symbol


def _perf_map(module, library) -> None:
    """Write /tmp/perf-<pid>.map for the functions of the lane kernel's object code.

    With ``numba.config.CACHE_DIR`` set (``auvtrack.jit``), Numba keeps a module's cache in
    ``<CACHE_DIR>/<folder>_<hash>/``: for the generated lanes module, next to ``kernels/``.
    """
    path = Path(module.__file__)
    nbc = sorted(path.parent.parent.glob(f"kernels_*/{path.stem}.run_lanes-*.nbc"))
    with tempfile.NamedTemporaryFile(suffix=".o") as f:
        f.write(_object_code(nbc[-1]))
        f.flush()
        syms = subprocess.run(["nm", "-S", f.name], capture_output=True, text=True, check=True).stdout
    lines = []
    for row in syms.splitlines():
        parts = row.split()
        if len(parts) == 4 and parts[2] in "TtWw":
            addr = library._codegen._engine.get_function_address(parts[3])
            if addr:
                lines.append(f"{addr:x} {int(parts[1], 16):x} {_demangle(parts[3])}\n")
    Path(f"/tmp/perf-{os.getpid()}.map").write_text("".join(lines))


def child(kind: str, seconds: float) -> None:
    """The profiled process (see the module docstring)."""
    from auvtrack.batch.runner import run_batch
    from auvtrack.scenario import load_scenario, paper_scenario_path
    from auvtrack.engine import kernels
    from auvtrack.simulation.pipeline import prepare

    preps = [prepare(load_scenario(paper_scenario_path(), {"sim.duration": 10.0, "seed": i, "uncertainty.D": 0.005 * i,
                                                           "controller.kind": kind})) for i in range(16)]
    run_batch(preps, backend="simd", workers=1)
    if seconds <= 0:  # the compile-only run
        return
    module = kernels.lanes_module(preps[0].key)
    _perf_map(module, next(iter(module.run_lanes.overloads.values())).library)
    t0 = time.time()
    while time.time() - t0 < seconds:
        run_batch(preps, backend="simd", workers=1)


def main() -> None:
    """Run the child under perf and print the share of samples per function."""
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--controller", default="fxtntsmc")
    ap.add_argument("--seconds", type=float, default=15.0)
    ap.add_argument("--child", action="store_true", help=argparse.SUPPRESS)
    ap.add_argument("--top", type=int, default=20)
    args = ap.parse_args()
    if args.child:
        child(args.controller, args.seconds)
        return
    cmd = [sys.executable, __file__, "--child", "--controller", args.controller]
    subprocess.run(cmd + ["--seconds", "0"], check=True)  # compile (or load) first, outside the samples
    with tempfile.TemporaryDirectory() as tmp:
        data = Path(tmp) / "perf.data"
        subprocess.run(["perf", "record", "-q", "-F", "2000", "-e", "cpu-clock", "-o", str(data), "--",
                        *cmd, "--seconds", str(args.seconds)], check=True)
        report = subprocess.run(["perf", "report", "-i", str(data), "--stdio", "--sort", "dso,sym"],
                                capture_output=True, text=True, check=True).stdout
        pid = re.search(r"\[JIT\] tid (\d+)", report)
        if pid:  # the child's map, read by the report: no longer needed
            Path(f"/tmp/perf-{pid.group(1)}.map").unlink(missing_ok=True)
    rows = [r for r in report.splitlines() if r.strip() and not r.startswith("#")]
    print(f"perf samples by function, {args.controller}, {args.seconds:g} s of 16-run SIMD batches:")
    print("\n".join(rows[:args.top]))


if __name__ == "__main__":
    main()
