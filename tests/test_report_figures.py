"""Figure text readable in an HTML report: the shown size of a figure's text follows from its width,
resolution and the figure area; make_readable scales the fonts of a wide figure until its smallest
text reaches MIN_TEXT_PX, checked on the PNG that savefig really writes; narrow figures are untouched."""
from __future__ import annotations

import struct

import pytest
from matplotlib.figure import Figure

from auvtrack.report import Report
from auvtrack.report_figures import FIGURE_AREA_PX, MIN_TEXT_PX, make_readable, shown_text_px, smallest_text_px

from report_check import IMG, check_html_report


def _png_width(path) -> int:
    data = path.read_bytes()
    assert data[12:16] == b"IHDR"
    return struct.unpack(">I", data[16:20])[0]


def _figure(width_in: float, panels: int = 3) -> Figure:
    fig = Figure(figsize=(width_in, 3.0), layout="constrained")
    for i, ax in enumerate(fig.subplots(1, panels, squeeze=False)[0]):
        ax.plot([0, 1, 2], [0, 1, 4], label=f"run {i}")
        ax.set_xlabel("t (s)", fontsize=9)
        ax.set_ylabel("x (m)", fontsize=9)
        ax.set_title(f"panel {i}", fontsize=9)
        ax.tick_params(labelsize=8)
        ax.legend(fontsize=8)
    return fig


def test_shown_size_is_the_point_size_at_the_dpi_scaled_down_to_the_area():
    assert shown_text_px(9.0, 5.0, 96.0, area_px=1000.0) == pytest.approx(12.0)  # 480 px wide: shown 1:1
    assert shown_text_px(9.0, 20.0, 100.0, area_px=1000.0) == pytest.approx(9.0 * 100 / 72 / 2)  # halved
    assert shown_text_px(8.0, 14.0, 120.0) == pytest.approx(8.0 / 72 * FIGURE_AREA_PX / 14.0)


@pytest.mark.parametrize("width_in, dpi", [(15.0, 120), (20.0, 120), (24.0, 200)])
def test_a_wide_figure_is_made_readable_as_measured_on_the_saved_png(tmp_path, width_in, dpi):
    fig = _figure(width_in, panels=int(width_in // 3))
    before = smallest_text_px(fig, dpi)
    assert before < MIN_TEXT_PX  # the case that needs it
    shown = make_readable(fig, dpi)
    assert shown >= MIN_TEXT_PX
    path = tmp_path / "f.png"
    fig.savefig(path, dpi=dpi, bbox_inches="tight")
    # independent of the estimate: the smallest font over the width savefig really wrote
    fig.draw_without_rendering()
    from matplotlib.text import Text

    smallest = min(t.get_fontsize() for t in fig.findobj(Text) if t.get_visible() and t.get_text().strip())
    assert shown_text_px(smallest, _png_width(path) / dpi, dpi) >= MIN_TEXT_PX * 0.99
    ticks = fig.axes[0].xaxis.get_major_ticks()
    assert ticks[0].label1.get_fontsize() == pytest.approx(smallest)  # the tick labels were the smallest: scaled


def test_a_narrow_figure_is_left_as_it_is():
    fig = _figure(6.0, panels=2)
    sizes = [ax.xaxis.label.get_fontsize() for ax in fig.axes]
    assert make_readable(fig, 120) >= MIN_TEXT_PX
    assert [ax.xaxis.label.get_fontsize() for ax in fig.axes] == sizes == [9.0, 9.0]


def test_report_figures_record_their_text_size_and_the_page_widens_the_figure_area(tmp_path):
    rep = Report(tmp_path, "T")
    rep.figure(_figure(16.0, panels=5), "wide", "a wide figure")
    rep.figure(_figure(5.0, panels=1), "narrow")
    rep.write()
    html = check_html_report(tmp_path)  # asserts every figure's data-text-px >= MIN_TEXT_PX
    shown = {src: float(px) for _, src, px in IMG.findall(html)}
    assert set(shown) == {"figures/wide.png", "figures/narrow.png"}
    assert shown["figures/wide.png"] == pytest.approx(MIN_TEXT_PX, rel=0.02)
    assert smallest_text_px(_figure(16.0, panels=5), 120) < MIN_TEXT_PX  # as drawn, it was not readable
