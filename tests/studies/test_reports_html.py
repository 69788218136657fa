"""Every study writes a self-contained report.html beside report.md, from the same Report blocks."""
from __future__ import annotations

import pytest
from markupsafe import escape

from auvtrack.studies.registry import all_studies
from auvtrack.report import Report, inline_html, markdown_blocks

from report_check import check_html_report


@pytest.mark.parametrize("name", sorted(all_studies()))
def test_each_study_writes_an_html_report_embedding_every_figure(name, tmp_path):
    report = all_studies()[name].run(tmp_path / name, quick=True)
    assert report == tmp_path / name / "report.md"
    html = check_html_report(tmp_path / name)
    title = report.read_text().splitlines()[0].removeprefix("# ")
    assert f"<title>{escape(title)}</title>" in html


def test_markdown_and_html_hold_the_same_blocks(tmp_path):
    from matplotlib.figure import Figure

    rep = Report(tmp_path, "T")
    rep.heading("Claims")
    rep.verdicts([("faster", "mixed", "x: 1 vs 2 s"), ("smoother", "supported", "tv")])
    rep.table(["metric", "A"], [["rmse_x", 1.5e-9], ["a|b", float("inf")]])
    rep.paragraph("`code_x` and **bold** and *it* with rho_inf and 3 * 4 * 5 <not a tag> [docs](docs/x.md)")
    fig = Figure()
    fig.subplots().plot([0, 1])
    rep.figure(fig, "f", "a caption")
    rep.scenario({"controller": {"kind": "ftsmc"}, "window": [0.0, float("inf")]}, "the scenario")
    rep.write()
    html = check_html_report(tmp_path)
    md = (tmp_path / "report.md").read_text()
    assert '<span class="verdict mixed">mixed</span>' in html and "- **faster**: mixed. x: 1 vs 2 s" in md
    assert "<td>1.5e-09</td>" in html and "| rmse_x | 1.5e-09 |" in md
    assert "<td>a|b</td>" in html and "| a\\|b | inf |" in md  # a pipe is escaped once, in Markdown only
    assert "&lt;not a tag&gt;" in html and "<not a tag>" not in html
    assert '"kind": "ftsmc"' in md and "&#34;kind&#34;: &#34;ftsmc&#34;" in html and "null" in md
    assert "<figcaption>a caption</figcaption>" in html and "*a caption*" in md
    with pytest.raises(ValueError, match="outside the report folder"):
        rep.image(__file__)


def test_inline_markup():
    assert inline_html("`a*b*c` **b** *i* x * y") == "<code>a*b*c</code> <strong>b</strong> <em>i</em> x * y"
    assert inline_html("settle_1cm_x <b> & [t](u.md)") == 'settle_1cm_x &lt;b&gt; &amp; <a href="u.md">t</a>'


def test_markdown_blocks_of_hand_written_markdown():
    text = "# Title\n\nA para\ncontinued.\n\n- one\n- two\n  more\n\n| a | b |\n|---|---|\n| 1 | x\\|y |\n\n```\ncode\n```\n"
    kinds = [(b.kind, b.data) for b in markdown_blocks(text)]
    assert kinds == [("heading", {"text": "Title", "level": 1}), ("paragraph", {"text": "A para continued."}),
                     ("bullets", {"items": ["one", "two more"]}),
                     ("table", {"headers": ["a", "b"], "rows": [["1", "x\\|y"]]}),
                     ("code", {"label": "", "text": "code"})]
