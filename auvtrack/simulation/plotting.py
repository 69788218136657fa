"""Figures of one run or of a comparison of runs (the paper's Figures 3-8).

Every ``fig_*`` function takes ``runs``: a list of ``(label, Result)`` pairs (a single
:class:`~auvtrack.simulation.result.Result` or a ``{label: Result}`` dict is accepted too), so the
same code draws one run or a controller comparison.  The reference is taken from the first run.
Figures are built with the object API (:class:`matplotlib.figure.Figure`, no pyplot state), so
they work headless and never open a window.
"""
from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any, Iterable, Mapping, Sequence, Union

import matplotlib
import numpy as np
from matplotlib.figure import Figure
from mpl_toolkits.mplot3d import Axes3D  # noqa: F401  (registers the "3d" projection)

if TYPE_CHECKING:  # pragma: no cover
    from .result import Result

    Runs = Union["Result", Mapping[str, "Result"], Sequence[tuple[str, "Result"]]]

AXES = ("x", "y", "z")
KINDS = ("trajectory3d", "positions", "velocities", "inputs", "errors", "chi", "overview")

STYLE: dict[str, Any] = {
    "font.size": 9, "axes.titlesize": 9, "axes.labelsize": 9, "legend.fontsize": 8,
    "xtick.labelsize": 8, "ytick.labelsize": 8, "lines.linewidth": 1.2,
    "axes.grid": True, "grid.alpha": 0.3, "grid.linestyle": ":", "legend.framealpha": 0.85,
    "savefig.bbox": "tight",
}
"""rcParams applied while a figure is built (clean, paper-like)."""

REF_STYLE = {"color": "k", "linestyle": "--", "linewidth": 1.0}
BASE_ENV_STYLE = {"color": "0.45", "linestyle": "--", "linewidth": 0.9}
POS_LABELS = {"x": "x (m)", "y": "y (m)", "z": "z (m)"}
ERR_LABELS = {"x": r"$e_x$ (m)", "y": r"$e_y$ (m)", "z": r"$e_z$ (m)"}
VEL_LABELS = {"u": "u (m/s)", "v": "v (m/s)", "w": "w (m/s)", "q": "q (rad/s)", "r": "r (rad/s)"}
TAU_LABELS = {"tau_u": r"$\tau_u$ (N)", "tau_q": r"$\tau_q$ (N$\cdot$m)", "tau_r": r"$\tau_r$ (N$\cdot$m)"}
CHI_LABELS = {a: rf"$\chi_{a} - \hat\chi_{a}$ (m/s$^2$)" for a in AXES}


def normalize_runs(runs: "Runs") -> list[tuple[str, "Result"]]:
    """Return ``runs`` as a list of ``(label, Result)`` pairs.

    Parameters
    ----------
    runs : Result, dict or sequence of (str, Result)
        One result (labelled by its controller), a ``{label: Result}`` mapping or pairs.

    Returns
    -------
    list of (str, Result)
        The labelled runs, in order.

    Raises
    ------
    ValueError
        If no run is given.
    """
    from .result import Result

    if isinstance(runs, Result):
        out = [(run_label(runs), runs)]
    elif isinstance(runs, Mapping):
        out = [(str(k), v) for k, v in runs.items()]
    else:
        out = [(str(k), v) for k, v in runs]
    if not out:
        raise ValueError("no runs to plot")
    return out


def run_label(res: "Result") -> str:
    """Return the default legend label of a result.

    Parameters
    ----------
    res : Result
        A simulation result.

    Returns
    -------
    str
        The scenario's controller kind, else its name, else ``"run"``.
    """
    sc = res.scenario if isinstance(res.scenario, Mapping) else {}
    ctrl = sc.get("controller")
    if isinstance(ctrl, Mapping) and ctrl.get("kind"):
        return str(ctrl["kind"])
    return str(sc.get("name") or "run")


def _new_figure(figsize: tuple[float, float]) -> Figure:
    return Figure(figsize=figsize, layout="constrained")


def _mask(res: "Result", t_range: tuple[float, float] | None) -> np.ndarray:
    t = res.t
    if t_range is None:
        return np.ones(t.size, dtype=bool)
    return (t >= t_range[0]) & (t <= t_range[1])


def _color(i: int) -> str:
    return f"C{i % 10}"


def _finish_time_axes(axes: Sequence, title: str | None, fig: Figure, legend: bool = True) -> None:
    for ax in axes:
        ax.grid(True)
    axes[-1].set_xlabel("t (s)")
    handles, labels = axes[0].get_legend_handles_labels()
    if handles and legend:
        axes[0].legend(loc="best")
    if title:
        fig.suptitle(title)


def _note(ax, text: str) -> None:
    ax.text(0.5, 0.5, text, transform=ax.transAxes, ha="center", va="center", color="0.4")


def _series_panel(ax, runs, channel: str, t_range, *, reference: str | None = None) -> None:
    """Draw one channel of every run (and optionally the reference channel of the first run)."""
    for i, (label, res) in enumerate(runs):
        if channel not in res:
            continue
        m = _mask(res, t_range)
        ax.plot(res.t[m], res[channel][m], color=_color(i), label=label)
    if reference is not None:
        res0 = runs[0][1]
        if reference in res0:
            m = _mask(res0, t_range)
            ax.plot(res0.t[m], res0[reference][m], label="reference", **REF_STYLE)


def _draw_trajectory3d(ax, runs, legend_loc: str = "upper left") -> None:
    res0 = runs[0][1]
    ax.plot(res0["xd"], res0["yd"], res0["zd"], label="reference", **REF_STYLE)
    for i, (label, res) in enumerate(runs):
        ax.plot(res["x"], res["y"], res["z"], color=_color(i), label=label)
        if res.t.size:
            ax.scatter([res["x"][0]], [res["y"][0]], [res["z"][0]], color=_color(i), marker="o", s=12)
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_zlabel("z (m)")
    ax.legend(loc=legend_loc)


def fig_trajectory3d(runs: "Runs", *, figsize: tuple[float, float] = (5.5, 4.5),
                     title: str | None = None) -> Figure:
    """3-D path of each run against the reference (paper Figure 3).

    Parameters
    ----------
    runs : Result, dict or sequence of (str, Result)
        Runs to draw; the reference comes from the first.
    figsize : tuple of float, optional
        Figure size in inches.
    title : str, optional
        Figure title.

    Returns
    -------
    matplotlib.figure.Figure
        One 3-D axes; start points are marked with dots.
    """
    runs = normalize_runs(runs)
    with matplotlib.rc_context(STYLE):
        fig = _new_figure(figsize)
        ax = fig.add_subplot(projection="3d")
        _draw_trajectory3d(ax, runs)
        if title:
            ax.set_title(title)
    return fig


def _time_figure(runs, panels: Sequence[tuple[str, str, str | None]], figsize, title, t_range) -> Figure:
    """Stacked time plots; ``panels`` = (channel, y label, reference channel or None)."""
    runs = normalize_runs(runs)
    with matplotlib.rc_context(STYLE):
        fig = _new_figure(figsize)
        axes = fig.subplots(len(panels), 1, sharex=True, squeeze=False)[:, 0]
        for ax, (ch, ylabel, ref) in zip(axes, panels):
            _series_panel(ax, runs, ch, t_range, reference=ref)
            ax.set_ylabel(ylabel)
        _finish_time_axes(axes, title, fig)
    return fig


def fig_positions(runs: "Runs", *, figsize: tuple[float, float] = (6.0, 5.5), title: str | None = None,
                  t_range: tuple[float, float] | None = None) -> Figure:
    """Positions x, y, z of each run against the reference, three panels (paper Figure 4).

    Parameters
    ----------
    runs : Result, dict or sequence of (str, Result)
        Runs to draw; the reference comes from the first.
    figsize : tuple of float, optional
        Figure size in inches.
    title : str, optional
        Figure title.
    t_range : tuple of float, optional
        Time interval (s) to show.

    Returns
    -------
    matplotlib.figure.Figure
        Three axes sharing the time axis.
    """
    panels = [(a, POS_LABELS[a], f"{a}d") for a in AXES]
    return _time_figure(runs, panels, figsize, title, t_range)


def fig_velocities(runs: "Runs", *, figsize: tuple[float, float] = (6.0, 7.5), title: str | None = None,
                   t_range: tuple[float, float] | None = None) -> Figure:
    """Body velocities u, v, w, q, r of each run, five panels (paper Figure 5).

    Parameters
    ----------
    runs : Result, dict or sequence of (str, Result)
        Runs to draw.
    figsize : tuple of float, optional
        Figure size in inches.
    title : str, optional
        Figure title.
    t_range : tuple of float, optional
        Time interval (s) to show.

    Returns
    -------
    matplotlib.figure.Figure
        Five axes sharing the time axis.
    """
    panels = [(c, lab, None) for c, lab in VEL_LABELS.items()]
    return _time_figure(runs, panels, figsize, title, t_range)


def fig_inputs(runs: "Runs", *, figsize: tuple[float, float] = (6.0, 5.5), title: str | None = None,
               t_range: tuple[float, float] | None = None) -> Figure:
    """Control inputs tau_u, tau_q, tau_r of each run, three panels (paper Figure 6).

    Parameters
    ----------
    runs : Result, dict or sequence of (str, Result)
        Runs to draw.
    figsize : tuple of float, optional
        Figure size in inches.
    title : str, optional
        Figure title.
    t_range : tuple of float, optional
        Time interval (s) to show.

    Returns
    -------
    matplotlib.figure.Figure
        Three axes sharing the time axis.
    """
    panels = [(c, lab, None) for c, lab in TAU_LABELS.items()]
    return _time_figure(runs, panels, figsize, title, t_range)


def _draw_error_panel(ax, runs, a: str, t_range, envelopes: bool) -> None:
    _series_panel(ax, runs, f"e{a}", t_range)
    if not envelopes:
        return
    base_done = False
    for i, (label, res) in enumerate(runs):
        m = _mask(res, t_range)
        t = res.t[m]
        if f"rho_{a}" in res:
            rho = res[f"rho_{a}"][m]
            ax.plot(t, rho, color=_color(i), linestyle="-.", linewidth=0.9, alpha=0.8,
                    label=rf"$\pm\rho$ ({label})")
            ax.plot(t, -rho, color=_color(i), linestyle="-.", linewidth=0.9, alpha=0.8)
        if f"rho1_{a}" in res and not base_done:  # the baseline envelope is the same for every run
            rho1 = res[f"rho1_{a}"][m]
            ax.plot(t, rho1, label=r"$\pm\rho_1$ (baseline)", **BASE_ENV_STYLE)
            ax.plot(t, -rho1, **BASE_ENV_STYLE)
            base_done = True
    ax.set_ylabel(ERR_LABELS[a])


def fig_errors(runs: "Runs", *, figsize: tuple[float, float] = (6.0, 5.5), title: str | None = None,
               t_range: tuple[float, float] | None = None, envelopes: bool = True) -> Figure:
    """Position errors e_x, e_y, e_z with the prescribed-performance envelopes (paper Figure 7).

    Parameters
    ----------
    runs : Result, dict or sequence of (str, Result)
        Runs to draw.
    figsize : tuple of float, optional
        Figure size in inches.
    title : str, optional
        Figure title.
    t_range : tuple of float, optional
        Time interval (s) to show.
    envelopes : bool, optional
        Draw ``±rho_*`` (dash-dot, the run's colour) for runs that log it, and the baseline
        ``±rho1_*`` (dashed grey) once if logged.

    Returns
    -------
    matplotlib.figure.Figure
        Three axes sharing the time axis.
    """
    runs = normalize_runs(runs)
    with matplotlib.rc_context(STYLE):
        fig = _new_figure(figsize)
        axes = fig.subplots(3, 1, sharex=True)
        for ax, a in zip(axes, AXES):
            _draw_error_panel(ax, runs, a, t_range, envelopes)
        _finish_time_axes(axes, title, fig)
    return fig


def _draw_chi_panel(ax, runs, a: str, t_range) -> bool:
    drawn = False
    for i, (label, res) in enumerate(runs):
        if f"chi_{a}" in res and f"chi_hat_{a}" in res:
            m = _mask(res, t_range)
            ax.plot(res.t[m], res[f"chi_{a}"][m] - res[f"chi_hat_{a}"][m], color=_color(i), label=label)
            drawn = True
    ax.set_ylabel(CHI_LABELS[a])
    return drawn


def fig_chi(runs: "Runs", *, figsize: tuple[float, float] = (6.0, 5.5), title: str | None = None,
            t_range: tuple[float, float] | None = None) -> Figure:
    """Approximation error chi - chi_hat of the lumped disturbance per axis (paper Figure 8).

    Only runs logging both ``chi_*`` and ``chi_hat_*`` are drawn; without any such run the
    panels say so instead of raising.

    Parameters
    ----------
    runs : Result, dict or sequence of (str, Result)
        Runs to draw.
    figsize : tuple of float, optional
        Figure size in inches.
    title : str, optional
        Figure title.
    t_range : tuple of float, optional
        Time interval (s) to show.

    Returns
    -------
    matplotlib.figure.Figure
        Three axes sharing the time axis.
    """
    runs = normalize_runs(runs)
    with matplotlib.rc_context(STYLE):
        fig = _new_figure(figsize)
        axes = fig.subplots(3, 1, sharex=True)
        for ax, a in zip(axes, AXES):
            if not _draw_chi_panel(ax, runs, a, t_range):
                _note(ax, "no chi / chi_hat channels")
        _finish_time_axes(axes, title, fig)
    return fig


def fig_overview(runs: "Runs", *, figsize: tuple[float, float] = (14.0, 7.0), title: str | None = None,
                 t_range: tuple[float, float] | None = None) -> Figure:
    """Grid of the main panels: 3-D path | positions | errors (with envelopes) | inputs.

    Parameters
    ----------
    runs : Result, dict or sequence of (str, Result)
        Runs to draw.
    figsize : tuple of float, optional
        Figure size in inches.
    title : str, optional
        Figure title.
    t_range : tuple of float, optional
        Time interval (s) of the time panels.

    Returns
    -------
    matplotlib.figure.Figure
        Ten axes: one 3-D axes spanning the first column, then three columns of three time
        panels (x, y, z positions; e_x, e_y, e_z; tau_u, tau_q, tau_r).
    """
    runs = normalize_runs(runs)
    with matplotlib.rc_context(STYLE):
        fig = _new_figure(figsize)
        fig.get_layout_engine().set(wspace=0.04)
        gs = fig.add_gridspec(3, 4, width_ratios=(1.7, 1, 1, 1))
        ax3 = fig.add_subplot(gs[:, 0], projection="3d")
        ax3.set_box_aspect(None, zoom=0.82)  # keep the z label clear of the next column
        _draw_trajectory3d(ax3, runs, legend_loc="upper center")
        cols = []
        for c in range(1, 4):
            first = fig.add_subplot(gs[0, c])
            cols.append([first] + [fig.add_subplot(gs[r, c], sharex=first) for r in (1, 2)])
        for r, a in enumerate(AXES):
            _series_panel(cols[0][r], runs, a, t_range, reference=f"{a}d")
            cols[0][r].set_ylabel(POS_LABELS[a])
            _draw_error_panel(cols[1][r], runs, a, t_range, True)
        for r, (ch, lab) in enumerate(TAU_LABELS.items()):
            _series_panel(cols[2][r], runs, ch, t_range)
            cols[2][r].set_ylabel(lab)
        for c, col in enumerate(cols):
            _finish_time_axes(col, None, fig, legend=(c == 1))  # runs are named in the 3-D legend
            for ax in col[:-1]:
                ax.tick_params(labelbottom=False)
        if title:
            fig.suptitle(title)
    return fig


FIGURES = {"trajectory3d": fig_trajectory3d, "positions": fig_positions, "velocities": fig_velocities,
           "inputs": fig_inputs, "errors": fig_errors, "chi": fig_chi, "overview": fig_overview}


def plot_runs(kind: str, runs: "Runs", **kw: Any) -> Figure:
    """Draw figure ``kind`` for ``runs``.

    Parameters
    ----------
    kind : str
        One of :data:`KINDS`.
    runs : Result, dict or sequence of (str, Result)
        Runs to draw.
    **kw
        Passed to the ``fig_<kind>`` function.

    Returns
    -------
    matplotlib.figure.Figure
        A new figure (never shown).

    Raises
    ------
    ValueError
        For an unknown kind.
    """
    try:
        fn = FIGURES[kind]
    except KeyError:
        raise ValueError(f"unknown plot kind {kind!r}; expected one of {', '.join(KINDS)}") from None
    return fn(runs, **kw)


def save_figure(fig: Figure, path_without_ext: str | Path, formats: Iterable[str] = ("png", "pdf"),
                dpi: int = 200) -> list[Path]:
    """Save ``fig`` once per format, creating the folder.

    Parameters
    ----------
    fig : matplotlib.figure.Figure
        Figure to save.
    path_without_ext : str or pathlib.Path
        Target path without extension, e.g. ``out/fig4_positions``.
    formats : iterable of str, optional
        File formats (extensions) to write.
    dpi : int, optional
        Resolution of raster formats.

    Returns
    -------
    list of pathlib.Path
        The files written.
    """
    base = Path(path_without_ext)
    base.parent.mkdir(parents=True, exist_ok=True)
    written = []
    for fmt in formats:
        path = base.with_name(f"{base.name}.{fmt}")
        meta = {"CreationDate": None} if fmt == "pdf" else None  # reproducible PDFs
        fig.savefig(path, format=fmt, dpi=dpi, metadata=meta)
        written.append(path)
    return written


__all__ = ["KINDS", "STYLE", "fig_trajectory3d", "fig_positions", "fig_velocities", "fig_inputs",
           "fig_errors", "fig_chi", "fig_overview", "plot_runs", "save_figure", "normalize_runs", "run_label"]
