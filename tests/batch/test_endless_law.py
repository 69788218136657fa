"""A plug-in law in an endless loop cannot hold a batch past Ctrl-C: the wait is bounded, the
stuck run is abandoned (None in ``BatchInterrupted.results``), the runs that stopped keep their
outcomes, and the process can end (``os._exit``, as the command line does)."""
from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
EXAMPLE = ROOT / "examples" / "plugin_controller.py"

DRIVER = textwrap.dedent("""
    import json, os, signal, sys, threading, time, warnings
    from auvtrack.batch.runner import BatchInterrupted, run_batch
    from auvtrack.interrupt import GRACE_S, abandoned
    from auvtrack.scenario import load_scenario
    from auvtrack.simulation.compiling import ensure_compiled
    from auvtrack.simulation.pipeline import prepare
    warnings.simplefilter("ignore")
    law, workers = sys.argv[1], int(sys.argv[2])
    looping = ["controller.kind=plugin", f"controller.module={law!r}", "sim.duration=3"]
    preps = [prepare(load_scenario("paper", looping)), prepare(load_scenario("paper", ["sim.duration=3"]))]
    ensure_compiled(preps)
    run_batch(preps[1:], workers=1)  # everything the well-behaved run loads or compiles, loaded before the clock
    threading.Timer(1.5, lambda: os.kill(os.getpid(), signal.SIGINT)).start()
    t0 = time.monotonic()
    try:
        run_batch(preps, workers=workers)
        print(json.dumps({"finished": True}))
    except BatchInterrupted as exc:
        print(json.dumps({"after": time.monotonic() - t0 - 1.5, "grace": GRACE_S, "abandoned": abandoned(),
                          "results": [None if r is None else r.status for r in exc.results]}))
    sys.stdout.flush()
    os._exit(0)
""")


@pytest.mark.parametrize("workers", [1, 2])
def test_ctrl_c_abandons_a_law_that_never_returns_and_keeps_the_rest(tmp_path, workers):
    law = tmp_path / "endless.py"
    law.write_text(EXAMPLE.read_text().replace("    return 0\n", "    while t > 0.5:\n        t = t + 0.0\n    return 0\n"))
    p = subprocess.run([sys.executable, "-c", DRIVER, str(law), str(workers)], cwd=tmp_path, capture_output=True,
                       text=True, timeout=600, env={**os.environ, "PYTHONPATH": str(ROOT)},
                       preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    assert p.returncode == 0, p.stderr
    out = json.loads(p.stdout.strip().splitlines()[-1])
    assert out.get("finished") is None, out
    assert out["abandoned"] and out["results"][0] is None
    assert out["after"] < out["grace"] + 3.0  # the grace period, not for ever
    # the other run finished or stopped at the request: its outcome is kept (serially it never started)
    assert out["results"][1] in (("ok", "interrupted") if workers > 1 else (None,)), out
