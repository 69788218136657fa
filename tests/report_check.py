"""Check a report folder: ``report.html`` is self-contained and embeds every figure of the folder."""
from __future__ import annotations

import base64
import re
from pathlib import Path

IMG = re.compile(r'<img src="data:image/png;base64,([A-Za-z0-9+/=]+)" alt="[^"]*" data-file="([^"]+)">')


def check_html_report(folder: Path, markdown: str = "report.md") -> str:
    """Assert the HTML page of ``folder`` embeds each PNG of ``figures/`` byte for byte; return its text."""
    html = (folder / "report.html").read_text(encoding="utf-8")
    assert html.startswith("<!DOCTYPE html>") and html.rstrip().endswith("</html>")
    embedded = {src: base64.b64decode(data) for data, src in IMG.findall(html)}
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
