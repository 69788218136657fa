"""Check a report folder: ``report.html`` is self-contained and embeds every figure of the folder."""
from __future__ import annotations

import base64
import re
from pathlib import Path

from auvtrack.report_figures import FIGURE_AREA_REM, MIN_TEXT_PX

IMG = re.compile(r'<img src="data:image/png;base64,([A-Za-z0-9+/=]+)" alt="[^"]*" data-file="([^"]+)"'
                 r'(?: data-text-px="([0-9.]+)")?>')


def check_html_report(folder: Path, markdown: str = "report.md") -> str:
    """Assert the HTML page of ``folder`` embeds each PNG of ``figures/`` byte for byte; return its text."""
    html = (folder / "report.html").read_text(encoding="utf-8")
    assert html.startswith("<!DOCTYPE html>") and html.rstrip().endswith("</html>")
    found = IMG.findall(html)
    embedded = {src: base64.b64decode(data) for data, src, _ in found}
    # every figure was made readable: its smallest text is shown >= MIN_TEXT_PX high in the figure area
    assert all(px and float(px) >= MIN_TEXT_PX for _, _, px in found), [(src, px) for _, src, px in found]
    assert f"width: min({FIGURE_AREA_REM}rem, calc(100vw - 2rem))" in html
    pngs = sorted(p.relative_to(folder).as_posix() for p in (folder / "figures").glob("*.png")) \
        if (folder / "figures").is_dir() else []
    assert sorted(embedded) == pngs, (sorted(embedded), pngs)
    for src, data in embedded.items():
        assert data == (folder / src).read_bytes(), src
    # self-contained: nothing is loaded from elsewhere (links to files are fine, sources are not)
    assert not re.search(r'<(img|script|link)[^>]+(src|href)="(?!data:)', html)
    md = (folder / markdown).read_text(encoding="utf-8")
    for src in pngs:  # the Markdown links the same figures
        assert f"]({src})" in md, src
    assert "Scenario and version" in html and "Scenario and version" in md
    assert re.search(r"auvtrack \d+\.\d+\.\d+ \(sources [0-9a-f]{12}\)", html)
    return html
