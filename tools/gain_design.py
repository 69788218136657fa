"""The generated table of ``docs/controllers.md``: gains designed for each vehicle with a known reach.

Every number is computed by :mod:`auvtrack.control.design` from the vehicle presets (their reach at
U0 from :mod:`auvtrack.plant.sixdof.reach`).  To refresh the document::

    python -m tools.gain_design render     # rewrite the generated block
    python -m tools.gain_design check      # exit 1 when it is stale

The block sits between ``<!-- BEGIN GENERATED gain-design ... -->`` and
``<!-- END GENERATED gain-design -->`` (the markers of :mod:`tools.findings`).
"""
from __future__ import annotations

import sys
from pathlib import Path

from tools.findings import BLOCK_RE
from auvtrack.report import fmt

ROOT = Path(__file__).resolve().parents[1]
DOC = ROOT / "docs" / "controllers.md"
CASES = (("remus100", 1.25), ("remus100_fossen", 1.25), ("remus600", None))
"""(design preset, U0 in m/s or None for the file's own): remus100 at the model-gap study's speed."""


def block_gain_design() -> str:
    """Markdown: per vehicle the reach, A of (D2), and per law omega and the designed gains."""
    import auvtrack.plant  # noqa: F401  (registers the 6-DOF truths' reach and torpedo presets)
    from auvtrack.control import design
    from auvtrack.vehicle.presets import get_preset

    lines = [f"e_ref = {fmt(design.DESIGN_ERROR, 3)} m, kappa = {fmt(design.REACH_FRACTION, 3)}; peak demands of the "
             "defaults from e_ref (D3): " + ", ".join(f"{k} {fmt(design.peak_demand(k), 4)} m/s²"
                                                      for k in design.designed_kinds()) + ".", "",
             "| design vehicle | U0 (m/s) | reach τ_u / τ_q / τ_r (N, N m, N m) | A (m/s²) | law | ω | designed gains |",
             "|---|---|---|---|---|---|---|"]
    for name, u0 in CASES:
        pre = get_preset(name, u0=u0)
        head = (f"`{name}`", fmt(pre.u0, 4), " / ".join(fmt(r, 4) for r in pre.reach))
        for i, kind in enumerate(design.designed_kinds()):
            d = design.design(kind, pre.m, pre.l, pre.reach)
            gains = ", ".join(f"{k} {fmt(v, 4)}" for k, v in d.gains.items() if k != "saturation")
            cells = head + (fmt(d.accel, 4),) if i == 0 else ("", "", "", "")
            lines.append(f"| {' | '.join(cells)} | {kind} | {fmt(d.omega, 4)} | {gains} |")
    return "\n".join(lines)


def blocks() -> dict:
    """Generated block name -> renderer (in docs/controllers.md)."""
    return {"gain-design": block_gain_design}


def render_text(text: str) -> str:
    """``text`` with every generated block of :func:`blocks` re-rendered (other generators' blocks left alone)."""
    table = blocks()

    def sub(m):
        name = m.group("name")
        if name not in table:
            return m.group(0)
        return m.group(1) + table[name]().rstrip() + "\n" + m.group(4)
    return BLOCK_RE.sub(sub, text)


def main(argv: list[str] | None = None) -> int:
    """``python -m tools.gain_design render | check``."""
    args = sys.argv[1:] if argv is None else argv
    old = DOC.read_text()
    new = render_text(old)
    if args == ["render"]:
        if new != old:
            DOC.write_text(new)
        print("changed: " + ("docs/controllers.md" if new != old else "nothing"))
        return 0
    if args == ["check"]:
        if new != old:
            print("stale generated block in docs/controllers.md (python -m tools.gain_design render)")
            return 1
        return 0
    print("usage: python -m tools.gain_design render | check", file=sys.stderr)
    return 2


if __name__ == "__main__":  # pragma: no cover
    raise SystemExit(main())
