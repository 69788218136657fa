"""The model-gap acceptance check of the shipped presets: every calm truth run of the study, with each preset.

    python tools/preset_acceptance.py [--suite auv-track-v2] [--quick] [--json FILE]

Prints one line per controller (runs completed / flown, infeasible tasks not flown, a missing
preset) and one per failed run (truth, reference, cause, time): :mod:`auvtrack.studies.preset_acceptance`.
"""
from __future__ import annotations

import argparse
import json
from collections import defaultdict
from dataclasses import asdict


def main(argv: list[str] | None = None) -> int:
    """Fly the check and print it; return 0 when every flown run completed, 1 otherwise."""
    from auvtrack.studies.preset_acceptance import acceptance

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--suite", default="auv-track-v2")
    ap.add_argument("--quick", action="store_true", help="the helix only, 20 s")
    ap.add_argument("--json", default=None, help="write the rows to this file")
    a = ap.parse_args(argv)
    rows = acceptance(a.suite, quick=a.quick)
    per = defaultdict(list)
    for r in rows:
        per[r.controller].append(r)
    for kind, mine in per.items():
        flown = [r for r in mine if r.status in ("ok", "failed")]
        ok = sum(r.status == "ok" for r in flown)
        skipped = sum(r.status == "infeasible" for r in mine)
        missing = any(r.status == "no preset" for r in mine)
        print(f"{kind}: " + (f"no preset {mine[0].preset}" if missing else
                             f"{ok}/{len(flown)} completed ({skipped} infeasible tasks not flown)"))
        for r in flown:
            if r.status != "ok":
                print(f"  {r.truth} {r.reference}: {r.cause} at {r.fail_time:.2f} s")
    if a.json:
        with open(a.json, "w") as fh:
            json.dump([asdict(r) for r in rows], fh, indent=1, default=str)
    return 0 if all(r.status != "failed" for r in rows) else 1


if __name__ == "__main__":
    raise SystemExit(main())
