"""Figure text that stays readable in an HTML report: the size a figure's text is shown at, and the fix.

An HTML report (``auvtrack/templates/report.html.j2``) shows each PNG at one image pixel per CSS
pixel, scaled down to fit its figure area (:data:`FIGURE_AREA_REM`, wider than the 68rem text
column).  Text of ``pt`` points in a figure ``w`` inches wide saved at ``dpi`` is then shown

    pt * dpi / 72 * min(1, area_px / (w * dpi))   CSS pixels high (:func:`shown_text_px`),

so a wide figure's text shrinks with the figure.  :func:`make_readable` scales a Matplotlib
figure's fonts until its smallest text is shown at least :data:`MIN_TEXT_PX` high (8 pt at 1:1 on
a 96 px/in screen), measured on the width the saved PNG will have (``bbox_inches="tight"``).
"""
from __future__ import annotations

from typing import Any

__all__ = ["FIGURE_AREA_REM", "FIGURE_AREA_PX", "MIN_TEXT_PX", "shown_text_px", "smallest_text_px", "make_readable"]

FIGURE_AREA_REM = 84
"""Width of an HTML report's figure area, rem (the text column is 68rem)."""
FIGURE_AREA_PX = 16 * FIGURE_AREA_REM
"""The figure area in CSS pixels (1rem = 16 px, the browsers' default)."""
MIN_TEXT_PX = 10.5
"""Smallest height, CSS px, at which a figure's text is shown in the figure area."""
TIGHT_PAD_IN = 0.1
"""Padding ``savefig(bbox_inches="tight")`` adds on each side, inches (Matplotlib's default)."""


def shown_text_px(pt: float, width_in: float, dpi: float, area_px: float = FIGURE_AREA_PX) -> float:
    """Height in CSS pixels of ``pt``-point text in a ``width_in``-inch PNG at ``dpi``, shown in ``area_px``.

    Parameters
    ----------
    pt : float
        Font size, points (1/72 in).
    width_in : float
        Width of the saved image, inches.
    dpi : float
        Pixels per inch of the saved image.
    area_px : float, optional
        CSS width the image is scaled down to when wider (one image pixel is one CSS pixel otherwise).

    Returns
    -------
    float
        ``pt * dpi / 72 * min(1, area_px / (width_in * dpi))``.
    """
    return pt * dpi / 72.0 * min(1.0, area_px / (width_in * dpi))


def _texts(fig: Any) -> tuple[list, list]:
    """The visible non-empty texts of ``fig``: (tick labels, every other text)."""
    from matplotlib.text import Text

    ticks: set[int] = set()
    for ax in fig.axes:
        for axis in _axes_of(ax):
            for tick in [*axis.get_major_ticks(), *axis.get_minor_ticks()]:
                ticks.update((id(tick.label1), id(tick.label2)))
    shown = [t for t in fig.findobj(Text) if t.get_visible() and t.get_text().strip()]
    return [t for t in shown if id(t) in ticks], [t for t in shown if id(t) not in ticks]


def _axes_of(ax: Any) -> list:
    return [getattr(ax, f"{n}axis") for n in "xyz" if hasattr(ax, f"{n}axis")]


def smallest_text_px(fig: Any, dpi: float, area_px: float = FIGURE_AREA_PX) -> float:
    """Height in CSS pixels at which the smallest text of ``fig`` is shown when saved tight at ``dpi``.

    Parameters
    ----------
    fig : matplotlib.figure.Figure
        The figure (drawn here, without rendering, to lay it out and create its ticks).
    dpi : float
        The resolution it will be saved at.
    area_px : float, optional
        CSS width of the figure area.

    Returns
    -------
    float
        :func:`shown_text_px` of its smallest font over the tight width; ``inf`` for a figure without text.
    """
    fig.draw_without_rendering()
    ticks, other = _texts(fig)
    sizes = [t.get_fontsize() for t in [*ticks, *other]]
    if not sizes:
        return float("inf")
    width = fig.get_tightbbox().width + 2 * TIGHT_PAD_IN
    return shown_text_px(min(sizes), width, dpi, area_px)


def make_readable(fig: Any, dpi: float, area_px: float = FIGURE_AREA_PX) -> float:
    """Scale every font of ``fig`` so that its smallest text is shown at least :data:`MIN_TEXT_PX` high.

    Tick labels are scaled through their axes (``set_tick_params``, so ticks made at the next
    draw keep the size); titles, labels, legends and annotations one by one.  A figure whose
    text is already large enough is left untouched.

    Parameters
    ----------
    fig : matplotlib.figure.Figure
        The figure, modified in place.
    dpi : float
        The resolution it will be saved at.
    area_px : float, optional
        CSS width of the figure area.

    Returns
    -------
    float
        The smallest text's shown height afterwards, CSS px (:func:`smallest_text_px`).
    """
    for _ in range(4):  # the tight width grows a little with the fonts: a few rounds converge
        shown = smallest_text_px(fig, dpi, area_px)
        if shown >= MIN_TEXT_PX * (1.0 - 1e-9):
            return shown
        k = MIN_TEXT_PX / shown * 1.001
        for ax in fig.axes:
            for axis in _axes_of(ax):
                major = axis.get_major_ticks()
                if major:
                    axis.set_tick_params(which="both", labelsize=major[0].label1.get_fontsize() * k)
        for t in _texts(fig)[1]:
            t.set_fontsize(t.get_fontsize() * k)
    return smallest_text_px(fig, dpi, area_px)
