"""Floating-point operation count of one RK4 step of a kernel, and the GPU throughput it predicts.

Usage::

    python benchmarks/op_count.py   # [--controller fxtntsmc] -> benchmarks/op_count.md and the block in docs/scaling.md

Compiles the single-run kernel in a child process with an empty cache (so Numba keeps the LLVM IR)
and counts, in the optimised IR of each function, the floating-point instructions (fadd, fsub,
fmul, fdiv, fneg, fcmp) and the calls of transcendental functions (a libmvec call counts its
lanes).  These are *static* counts: every branch counts once (an upper bound for branchy code such
as the envelope's risk loop) and a loop body counts once (a lower bound for the RBF loops over the
neurons and the RK4 updates over the state), so the per-step figure is an estimate of the order of
magnitude, stated with that basis; a libmvec call counts all its lanes, padding included.  One RK4
step is four stages (each calling the plant's ``rhs``) plus the loop body of ``run``.

The GPU prediction divides a current data-centre GPU's peak FP64 rate (NVIDIA datasheets; FMA =
2 flops) by the flops of one 10 s run, with a transcendental costing ``TRANSCENDENTAL_FLOPS``
(libdevice's FP64 exp, sin, pow are polynomial evaluations of that order), at the fractions of peak
in ``EFFICIENCIES`` (branchy, register-hungry code; ``docs/scaling.md`` explains why).
"""
from __future__ import annotations

import argparse
import json
import os
import re
import subprocess
import sys
import tempfile
from collections import Counter
from pathlib import Path

GPUS = {  # name: (peak FP64 non-tensor, flop/s; memory bandwidth, byte/s); NVIDIA datasheets
    "NVIDIA H100 SXM": (34e12, 3.35e12),
    "NVIDIA A100 SXM": (9.7e12, 2.04e12),
}
TRANSCENDENTAL_FLOPS = 30
EFFICIENCIES = (0.1, 0.3)
STEPS_PER_RUN = 10_000  # a 10 s run at dt = 1 ms, as in the batch benchmark
BEGIN, END = "<!-- op_count.py: begin (generated, do not edit) -->", "<!-- op_count.py: end -->"

CHILD = r"""
import json, re, sys
from collections import Counter
from auvtrack.scenario import load_scenario, paper_scenario_path
from auvtrack.simulation.pipeline import prepare, run_prepared
from auvtrack.engine import kernels
prep = prepare(load_scenario(paper_scenario_path(), {"controller.kind": sys.argv[1], "sim.duration": 0.01}))
run_prepared(prep)
run = kernels.kernel(prep.key)
ir = run.inspect_llvm(run.signatures[0])
out = {}
for f in re.split(r"\ndefine ", ir)[1:]:
    name = re.match(r"[^@]*@([\w.$]+)\(", f)
    if not name:
        continue
    name = name.group(1)
    ops = Counter(re.findall(r"= (fadd|fsub|fmul|fdiv|fneg|fcmp) ", f))
    calls = Counter()
    for callee, vec in re.findall(r"call [^@\n]*@(_ZGV[de]N(\d)\w+|llvm\.(?:pow|sin|cos|exp|log)\.f64|pow|sin|cos|exp|"
                                  r"tanh|atanh|log1p|sincos)\(", f):
        calls[callee] += int(vec) if vec else 1
    out[name] = {"ops": dict(ops), "transcendental": dict(calls)}
sizes = {"plant state": prep.plant.x0.size, "controller state": prep.controller.x0.size,
         "controller gains": prep.cp.size, "plant parameters": prep.pp.size, "nominal vehicle": prep.vp_nom.size,
         "reference": prep.ref_p.size, "disturbance rows": prep.environment.rows.size,
         "metrics accumulator": 49}
print(json.dumps({"functions": out, "sizes": sizes}))
"""


def counts(controller: str) -> dict:
    """Static FP instruction counts per function of the kernel of ``controller`` on the 5-DOF plant."""
    with tempfile.TemporaryDirectory() as tmp:
        env = {**os.environ, "AUVTRACK_CACHE_DIR": tmp, "PYTHONPATH": str(Path(__file__).resolve().parents[1])}
        proc = subprocess.run([sys.executable, "-c", CHILD, controller], env=env, cwd=tmp, capture_output=True,
                              text=True)
    if proc.returncode != 0:
        raise SystemExit(proc.stderr[-2000:])
    return json.loads(proc.stdout.strip().splitlines()[-1])


def _part(doc: dict, part: str) -> tuple[int, int]:
    for name, rec in doc.items():
        if re.search(rf"\d{part}B\d|\d{len(part)}{part}B", name) or name.endswith(part):
            return sum(rec["ops"].values()), sum(rec["transcendental"].values())
    return 0, 0


def main() -> None:
    """Count, estimate, write benchmarks/op_count.md."""
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--controller", default="fxtntsmc")
    args = ap.parse_args()
    full = counts(args.controller)
    doc, sizes = full["functions"], full["sizes"]
    stage_ops, stage_tr = _part(doc, "stage")
    rhs_ops, rhs_tr = _part(doc, "rhs")  # the plant's right-hand side, a call from each stage
    run_ops, run_tr = _part(doc, "run")
    step_ops = 4 * (stage_ops + rhs_ops) + run_ops
    step_tr = 4 * (stage_tr + rhs_tr) + run_tr
    step_flops = step_ops + TRANSCENDENTAL_FLOPS * step_tr
    run_flops = STEPS_PER_RUN * step_flops
    lines = ["# Operation count of one RK4 step (generated by `python benchmarks/op_count.py`)", "",
             f"Kernel: {args.controller} on the 5-DOF plant, Section 4 scenario. Static counts in the optimised LLVM "
             "IR (every branch once, every loop body once; see the script's docstring).", "",
             "| function | FP instructions | transcendental evaluations |", "|---|---|---|"]
    for name, rec in sorted(doc.items(), key=lambda kv: -sum(kv[1]["ops"].values())):
        n = sum(rec["ops"].values())
        if n < 20:
            continue
        short = re.sub(r"^_ZN\d+", "", name)
        short = re.sub(r"B\d.*$", "", short)
        lines.append(f"| `{short[:70]}` | {n} ({', '.join(f'{k} {v}' for k, v in sorted(rec['ops'].items()))}) | "
                     f"{sum(rec['transcendental'].values())} |")
    lines += ["", f"One RK4 step = 4 stages (each with the plant's `rhs`) + the loop of `run`: about {step_ops} FP instructions and {step_tr} "
              f"transcendental evaluations; at {TRANSCENDENTAL_FLOPS} flops each, about {step_flops:.0f} flops per "
              f"step, {run_flops:.2e} per 10 s run ({STEPS_PER_RUN} steps).", "",
              "| GPU | peak FP64 | runs / s at peak | at " + " and ".join(f"{e:.0%}" for e in EFFICIENCIES)
              + " of peak |", "|---|---|---|---|"]
    for gpu, (peak, _bw) in GPUS.items():
        lines.append(f"| {gpu} | {peak / 1e12:.1f} TFLOP/s | {peak / run_flops:,.0f} | "
                     + " to ".join(f"{e * peak / run_flops:,.0f}" for e in EFFICIENCIES) + " |")
    state = sizes["plant state"] + sizes["controller state"]
    ro = {k: v for k, v in sizes.items() if k not in ("plant state", "controller state", "metrics accumulator")}
    lines += ["", f"Per run: {state} integrated states ({sizes['plant state']} plant, {sizes['controller state']} "
              f"controller), so the RK4 loop keeps about {6 * state} doubles live (state, trial state, four stage "
              f"derivatives), plus a metrics accumulator of {sizes['metrics accumulator']}; read-only data "
              f"{sum(ro.values())} doubles ({', '.join(f'{k} {v}' for k, v in ro.items())}).  Each FP instruction "
              "counts as one flop (the CPU code has no FMA contraction)."]
    out = Path(__file__).resolve().parent / "op_count.md"
    out.write_text("\n".join(lines) + "\n")
    scaling = Path(__file__).resolve().parents[1] / "docs" / "scaling.md"
    if scaling.is_file():  # the generated block of docs/scaling.md
        text = scaling.read_text()
        a, b = text.find(BEGIN), text.find(END)
        if a >= 0 and b > a:
            scaling.write_text(text[:a + len(BEGIN)] + "\n" + "\n".join(lines[2:]) + "\n" + text[b:])
    print("\n".join(lines))


if __name__ == "__main__":
    main()
