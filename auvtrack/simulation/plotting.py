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

import math

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

REF_STYLE = {"color": "k", "linestyle": "--", "linewidth": 1.0, "zorder": 5}  # on top: runs that track it cover it
BASE_ENV_STYLE = {"color": "0.45", "linestyle": "--", "linewidth": 0.9}
POS_LABELS = {"x": "x (m)", "y": "y (m)", "z": "z (m, positive down)"}
VP_LABEL = r"virtual point $\eta_1$"
CG_STYLE = {"linewidth": 0.6, "alpha": 0.55, "linestyle": "-"}
START_MARKERS = ("o", "s", "^", "D", "v")
AXIS_STYLES = ("-", "--", ":")
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


def virtual_point_track(res: "Result") -> np.ndarray:
    """Logged path of the virtual point eta1 = eta_d + e, the point every controller tracks.

    The position channels ``x, y, z`` are the vehicle's centre of gravity; the virtual point lies
    ``vehicle.l`` ahead of it on the body axis (paper eq. 2).  Since ``ex, ey, ez`` are logged
    as eta1 - eta_d, the virtual point is recovered exactly, without re-deriving the kinematics.

    Parameters
    ----------
    res : Result
        A simulation result.

    Returns
    -------
    numpy.ndarray
        Shape ``(len(res), 3)``: x, y, z of eta1 (m, NED).
    """
    return np.column_stack([res[f"{a}d"] + res[f"e{a}"] for a in AXES]) if len(res) else np.zeros((0, 3))


def lever_arm(res: "Result") -> float | None:
    """The virtual-point offset ``vehicle.l`` (m) recorded in a result's scenario, if any.

    Parameters
    ----------
    res : Result
        A simulation result.

    Returns
    -------
    float or None
        ell (m), or ``None`` when the scenario does not record it.
    """
    sc = res.scenario if isinstance(res.scenario, Mapping) else {}
    for src in ((sc.get("resolved") or {}).get("vehicle"), sc.get("vehicle")):
        if isinstance(src, Mapping) and isinstance(src.get("l"), (int, float)):
            return float(src["l"])
    return None


def _vp_title(runs) -> str:
    ell = lever_arm(runs[0][1])
    where = f"{ell:g} m ahead of the CG" if ell is not None else "ahead of the CG"
    return rf"virtual point $\eta_1$ ({where}) vs reference $\eta_d$; thin: centre of gravity"


def _draw_trajectory3d(ax, runs, cg: bool = True) -> None:
    """Virtual points (and CGs), then the reference on top: it is covered wherever tracking is exact."""
    ax.computed_zorder = False  # draw in call order, so the dashed reference stays visible
    for i, (label, res) in enumerate(runs):
        vp = virtual_point_track(res)
        if cg:
            ax.plot(res["x"], res["y"], res["z"], color=_color(i), label=f"{label}: CG", **CG_STYLE)
        ax.plot(vp[:, 0], vp[:, 1], vp[:, 2], color=_color(i), label=f"{label}: {VP_LABEL}")
    res0 = runs[0][1]
    ax.plot(res0["xd"], res0["yd"], res0["zd"], label=r"reference $\eta_d$", **REF_STYLE)
    if len(res0):
        ax.scatter([res0["xd"][0]], [res0["yd"][0]], [res0["zd"][0]], color="k", marker="x", s=30,
                   label=r"$\eta_d(0)$")
    for i, (label, res) in enumerate(runs):
        if res.t.size:  # hollow markers of decreasing size: every run's start stays visible
            vp0 = virtual_point_track(res)[0]
            ax.scatter([vp0[0]], [vp0[1]], [vp0[2]], facecolors="none", edgecolors=_color(i),
                       marker=START_MARKERS[i % len(START_MARKERS)], s=max(70 - 25 * i, 20), linewidths=1.3,
                       label=f"{label}: start")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_zlabel("z (m, positive down)")
    ax.invert_zaxis()  # NED: z points down, so up in the figure is up in the water


def fig_trajectory3d(runs: "Runs", *, figsize: tuple[float, float] = (6.0, 5.0),
                     title: str | None = None, cg: bool = True) -> Figure:
    """3-D path of each run's virtual point against the reference (paper Figure 3).

    The controllers track the virtual point eta1 (``vehicle.l`` ahead of the centre of gravity,
    paper eq. 2), so that is what is drawn against eta_d; the CG path is a thin line of the same
    colour.  The z axis points down (NED).

    Parameters
    ----------
    runs : Result, dict or sequence of (str, Result)
        Runs to draw; the reference comes from the first.
    figsize : tuple of float, optional
        Figure size in inches.
    title : str, optional
        Figure title (default: what is drawn).
    cg : bool, optional
        Also draw the centre of gravity (thin line).

    Returns
    -------
    matplotlib.figure.Figure
        One 3-D axes; each run's start is a hollow marker of its own shape and size.
    """
    runs = normalize_runs(runs)
    with matplotlib.rc_context(STYLE):
        fig = _new_figure(figsize)
        ax = fig.add_subplot(projection="3d")
        _draw_trajectory3d(ax, runs, cg=cg)
        ax.set_title(title or _vp_title(runs), fontsize=8)
        fig.legend(*ax.get_legend_handles_labels(), loc="outside lower center", ncol=3, fontsize=7)
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


def _position_panel(ax, runs, i: int, t_range, cg: bool) -> None:
    """Reference, then each run's virtual point (and its CG, thin) on axis ``AXES[i]``."""
    a = AXES[i]
    res0 = runs[0][1]
    m0 = _mask(res0, t_range)
    ax.plot(res0.t[m0], res0[f"{a}d"][m0], label=r"reference $\eta_d$", **REF_STYLE)
    for k, (label, res) in enumerate(runs):
        m = _mask(res, t_range)
        ax.plot(res.t[m], virtual_point_track(res)[m, i], color=_color(k), label=f"{label}: {VP_LABEL}")
        if cg:
            ax.plot(res.t[m], res[a][m], color=_color(k), label=f"{label}: CG", **CG_STYLE)
    ax.set_ylabel(POS_LABELS[a])


def fig_positions(runs: "Runs", *, figsize: tuple[float, float] = (6.0, 5.5), title: str | None = None,
                  t_range: tuple[float, float] | None = None, cg: bool = True) -> Figure:
    """Virtual-point position x, y, z of each run against the reference, three panels (paper Figure 4).

    The controllers track the virtual point eta1 = eta_d + e (``vehicle.l`` ahead of the centre
    of gravity); plotting the CG instead would show a lag and a depth offset that is not a
    tracking error.  The CG is drawn as a thin line of the run's colour.

    Parameters
    ----------
    runs : Result, dict or sequence of (str, Result)
        Runs to draw; the reference comes from the first.
    figsize : tuple of float, optional
        Figure size in inches.
    title : str, optional
        Figure title (default: what is drawn).
    t_range : tuple of float, optional
        Time interval (s) to show.
    cg : bool, optional
        Also draw the centre of gravity (thin line).

    Returns
    -------
    matplotlib.figure.Figure
        Three axes sharing the time axis.
    """
    runs = normalize_runs(runs)
    with matplotlib.rc_context(STYLE):
        fig = _new_figure(figsize)
        axes = fig.subplots(3, 1, sharex=True)
        for i, ax in enumerate(axes):
            _position_panel(ax, runs, i, t_range, cg)
        _finish_time_axes(axes, title or _vp_title(runs), fig, legend=False)
        fig.legend(*axes[0].get_legend_handles_labels(), loc="outside lower center", ncol=3, fontsize=7)
    return fig


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


def steady_start(runs: "Runs", steady_from: float) -> float:
    """Start (s) of the steady-state panels: ``steady_from``, or half the shortest run if it ends sooner.

    Parameters
    ----------
    runs : Result, dict or sequence of (str, Result)
        Runs to draw.
    steady_from : float
        Requested start of the steady state (s).

    Returns
    -------
    float
        The start actually used.
    """
    ends = [float(res.t[-1]) for _, res in normalize_runs(runs) if res.t.size]
    if not ends:
        return float(steady_from)
    t_end = min(ends)
    return float(steady_from) if t_end > steady_from else 0.5 * t_end


def total_variation_rate(t: np.ndarray, x: np.ndarray) -> float:
    """Total variation of the samples ``x`` per second, sum |x[k+1] - x[k]| / (t[-1] - t[0]).

    Parameters
    ----------
    t, x : numpy.ndarray
        Sample times (s) and values; non-finite samples are ignored.

    Returns
    -------
    float
        Variation per second (units of x per s); 0 for fewer than two finite samples.
    """
    ok = np.isfinite(x) & np.isfinite(t)
    t, x = t[ok], x[ok]
    if t.size < 2 or t[-1] <= t[0]:
        return 0.0
    return float(np.abs(np.diff(x)).sum() / (t[-1] - t[0]))


def _smooth_last(runs, channel: str, t_range) -> list[int]:
    """Run indices ordered by decreasing variation of ``channel`` on ``t_range``: the smoothest is drawn last."""
    def tv(res):
        if channel not in res:
            return 0.0
        m = _mask(res, t_range)
        return total_variation_rate(res.t[m], res[channel][m])

    return sorted(range(len(runs)), key=lambda k: -tv(runs[k][1]))


def _input_panel(ax, runs, channel: str, t_range, order: Sequence[int]) -> None:
    for z, k in enumerate(order):
        label, res = runs[k]
        if channel not in res:
            continue
        m = _mask(res, t_range)
        ax.plot(res.t[m], res[channel][m], color=_color(k), label=label, zorder=2 + z)


def fig_inputs(runs: "Runs", *, figsize: tuple[float, float] = (9.0, 5.5), title: str | None = None,
               t_range: tuple[float, float] | None = None, steady_from: float | None = 20.0) -> Figure:
    """Control inputs tau_u, tau_q, tau_r of each run, with a steady-state column (paper Figure 6).

    The start-up spikes (hundreds of N) set the scale of a whole-run plot, which hides the
    chattering the controllers are compared on; the right-hand column shows t >= ``steady_from``
    on its own scale.  In every panel the runs are drawn in order of decreasing total variation
    on the steady-state interval, so the smoothest line is on top.

    Parameters
    ----------
    runs : Result, dict or sequence of (str, Result)
        Runs to draw.
    figsize : tuple of float, optional
        Figure size in inches.
    title : str, optional
        Figure title.
    t_range : tuple of float, optional
        Time interval (s) of the left-hand column.
    steady_from : float or None, optional
        Start (s) of the steady-state column (:func:`steady_start`: half the shortest run if
        that ends sooner); ``None`` draws the left-hand column only.

    Returns
    -------
    matplotlib.figure.Figure
        Three axes sharing the time axis, plus three steady-state axes unless ``steady_from`` is None.
    """
    runs = normalize_runs(runs)
    ncol = 1 if steady_from is None else 2
    with matplotlib.rc_context(STYLE):
        fig = _new_figure(figsize if ncol == 2 else (6.0, figsize[1]))
        grid = fig.subplots(3, ncol, sharex="col", squeeze=False)
        t_ss = None if steady_from is None else steady_start(runs, steady_from)
        ss_range = None if t_ss is None else (t_ss, t_range[1] if t_range else math.inf)
        for r, (ch, lab) in enumerate(TAU_LABELS.items()):
            order = _smooth_last(runs, ch, ss_range or t_range)
            _input_panel(grid[r, 0], runs, ch, t_range, order)
            grid[r, 0].set_ylabel(lab)
            if ncol == 2:
                _input_panel(grid[r, 1], runs, ch, ss_range, order)
                grid[r, 1].set_ylabel(lab)
        _finish_time_axes(grid[:, 0], title, fig, legend=False)
        handles = dict(zip(*reversed(grid[0, 0].get_legend_handles_labels())))  # label -> handle
        named = [lab for lab, _ in runs if lab in handles]
        if named:
            grid[0, 0].legend([handles[lab] for lab in named], named, loc="best")  # in run order
        if ncol == 2:
            _finish_time_axes(grid[:, 1], None, fig, legend=False)
            grid[0, 1].set_title(f"steady state, t ≥ {t_ss:g} s (own scale; smoothest line on top)")
            grid[0, 0].set_title("whole run")
    return fig


def _axis_envelope(res, a: str, m) -> tuple[np.ndarray, np.ndarray] | None:
    """(rho, rho1 or None) of axis ``a`` on mask ``m`` if the run logs a finite envelope."""
    if f"rho_{a}" not in res:
        return None
    rho = res[f"rho_{a}"][m]
    if not np.isfinite(rho).any():  # envelope.kind = "none" logs NaN
        return None
    rho1 = res[f"rho1_{a}"][m] if f"rho1_{a}" in res else None
    return rho, rho1


def _draw_error_panel(ax, runs, a: str, t_range, envelopes: bool) -> None:
    _series_panel(ax, runs, f"e{a}", t_range)
    ax.set_ylabel(ERR_LABELS[a])
    if not envelopes:
        return
    base_done = False
    for i, (label, res) in enumerate(runs):
        m = _mask(res, t_range)
        env = _axis_envelope(res, a, m)
        if env is None:
            continue
        t, (rho, rho1) = res.t[m], env
        ax.plot(t, rho, color=_color(i), linestyle="-.", linewidth=0.9, alpha=0.8, label=rf"$\pm\rho$ ({label})")
        ax.plot(t, -rho, color=_color(i), linestyle="-.", linewidth=0.9, alpha=0.8)
        if rho1 is not None and not base_done:  # the baseline envelope is the same for every run
            ax.plot(t, rho1, label=r"$\pm\rho_1$ (baseline)", **BASE_ENV_STYLE)
            ax.plot(t, -rho1, **BASE_ENV_STYLE)
            base_done = True


def _draw_log_error_panel(ax, runs, a: str, t_range) -> None:
    """|e_a| of every run and the envelope rho_a, rho1_a on a log scale: the envelope stays visible."""
    base_done = False
    for i, (label, res) in enumerate(runs):
        m = _mask(res, t_range)
        t = res.t[m]
        env = _axis_envelope(res, a, m)
        if env is not None:
            rho, rho1 = env
            if rho1 is not None and not base_done:
                ax.plot(t, rho1, label="_baseline", **BASE_ENV_STYLE)
                base_done = True
            ax.plot(t, rho, color=_color(i), linestyle="-.", linewidth=0.9, alpha=0.8, label=f"_rho {label}")
        ax.plot(t, np.abs(res[f"e{a}"][m]), color=_color(i), label=f"_{label}")
    ax.set_yscale("log")
    ax.set_ylabel(rf"$|e_{a}|$ (m, log)")


def ratio_text(value: float, digits: int = 2) -> str:
    """``value`` with ``digits`` significant digits, more where rounding would carry it across 1.

    A ratio |e|/rho of 0.9964 is inside the envelope: it reads ``0.996``, never ``1``; 1.004
    reads ``1.004``, never ``1``.

    Parameters
    ----------
    value : float
        The ratio.
    digits : int, optional
        Significant digits when rounding keeps the value's side of 1.

    Returns
    -------
    str
        The text.
    """
    if not math.isfinite(value):
        return str(value)
    for n in range(digits, 16):
        text = f"{value:.{n}g}"
        if (float(text) < 1.0) == (value < 1.0) and (float(text) > 1.0) == (value > 1.0):
            return text
    return repr(value)


def _draw_ratio_panel(ax, runs, t_range) -> list[str]:
    """|e_i| / rho_i per axis for the runs with an envelope (a run fails where it reaches 1); the peaks."""
    peaks = []
    for i, (label, res) in enumerate(runs):
        m = _mask(res, t_range)
        run_peaks = []
        for a, ls in zip(AXES, AXIS_STYLES):
            env = _axis_envelope(res, a, m)
            if env is None:
                continue
            ratio = np.abs(res[f"e{a}"][m]) / env[0]
            ax.plot(res.t[m], ratio, color=_color(i), linestyle=ls, linewidth=1.0, label=f"_{label} {a}")
            if np.isfinite(ratio).any():
                run_peaks.append(f"{a} {ratio_text(float(np.nanmax(ratio)))}")
        if run_peaks:
            peaks.append(f"{label}: " + ", ".join(run_peaks))
    ax.axhline(1.0, color="k", linewidth=0.9, label="_boundary")
    ax.set_yscale("log")
    if peaks:
        ax.set_ylim(top=10.0)
    ax.set_ylabel(r"$|e_i| / \rho_i$ (log)")
    return peaks


def _draw_widening_panel(ax, runs, t_range) -> bool:
    """The flexible part rho_bar = rho - rho1 of the envelope (eq. 25), per axis."""
    drawn = False
    for i, (label, res) in enumerate(runs):
        m = _mask(res, t_range)
        for a, ls in zip(AXES, AXIS_STYLES):
            env = _axis_envelope(res, a, m)
            if env is None or env[1] is None:
                continue
            ax.plot(res.t[m], env[0] - env[1], color=_color(i), linestyle=ls, linewidth=1.0, label=f"_{label} {a}")
            drawn = True
    ax.set_ylabel(r"$\bar\rho_i = \rho_i - \rho_{1,i}$ (m)")
    return drawn


def _errors_legend(fig, ax) -> None:
    """One legend below the figure: runs and envelopes, the axis line styles, the failure boundary."""
    from matplotlib.lines import Line2D

    handles, labels = ax.get_legend_handles_labels()
    for a, ls in zip(AXES, AXIS_STYLES):
        handles.append(Line2D([], [], color="0.3", linestyle=ls, linewidth=1.0))
        labels.append(f"axis {a} (bottom row)")
    handles.append(Line2D([], [], color="k", linewidth=0.9))
    labels.append(r"$|e_i| = \rho_i$: failure")
    fig.legend(handles, labels, loc="outside lower center", ncol=4, fontsize=7)


def fig_errors(runs: "Runs", *, figsize: tuple[float, float] = (10.0, 8.0), title: str | None = None,
               t_range: tuple[float, float] | None = None, envelopes: bool = True) -> Figure:
    """Position errors with the prescribed-performance envelopes (paper Figure 7), readable at every scale.

    Left column: e_x, e_y, e_z with ``±rho`` (dash-dot, the run's colour) and the baseline
    ``±rho1`` (dashed grey), as in the paper.  After the envelope has shrunk to its final
    width (5 mm in Section 4) that is invisible on a metre scale, so the right column shows
    |e| with rho and rho1 on a log scale; the bottom row shows |e_i| / rho_i on a log scale (a
    run fails when it reaches 1) and the flexible part rho_bar = rho - rho1 of the envelope
    (paper eq. 25).  Runs without an envelope (FTSMC, ``envelope.kind = "none"``) appear in
    the error panels only.

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
        Draw the envelopes and the two envelope panels; ``False`` gives the three error panels only.

    Returns
    -------
    matplotlib.figure.Figure
        Eight axes (error | log |e| per axis, then |e|/rho | rho_bar), or three without envelopes.
    """
    runs = normalize_runs(runs)
    with matplotlib.rc_context(STYLE):
        fig = _new_figure(figsize if envelopes else (6.0, 5.5))
        if not envelopes:
            axes = fig.subplots(3, 1, sharex=True)
            for ax, a in zip(axes, AXES):
                _draw_error_panel(ax, runs, a, t_range, False)
            _finish_time_axes(axes, title, fig)
            return fig
        grid = fig.subplots(4, 2, sharex=True)
        for r, a in enumerate(AXES):
            _draw_error_panel(grid[r, 0], runs, a, t_range, True)
            _draw_log_error_panel(grid[r, 1], runs, a, t_range)
        peaks = _draw_ratio_panel(grid[3, 0], runs, t_range)
        if not peaks:
            _note(grid[3, 0], "no run logs an envelope")
        if not _draw_widening_panel(grid[3, 1], runs, t_range):
            _note(grid[3, 1], "no run logs a flexible envelope")
        for c in range(2):
            _finish_time_axes(grid[:, c], None, fig, legend=False)
        _errors_legend(fig, grid[0, 0])
        grid[0, 0].set_title("errors and envelopes (linear)")
        grid[0, 1].set_title("|e| and envelopes (log scale)")
        grid[3, 0].set_title("|e| / envelope; max " + "; ".join(peaks) if peaks else "|e| / envelope", fontsize=7)
        grid[3, 1].set_title("flexible part of the envelope (risk monitor and start widening)", fontsize=7)
        if title:
            fig.suptitle(title)
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
    """Grid of the main panels: 3-D path | virtual-point positions | errors (with envelopes) | inputs.

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
        _draw_trajectory3d(ax3, runs, cg=False)
        ax3.legend(loc="upper center", fontsize=7)
        cols = []
        for c in range(1, 4):
            first = fig.add_subplot(gs[0, c])
            cols.append([first] + [fig.add_subplot(gs[r, c], sharex=first) for r in (1, 2)])
        for r, a in enumerate(AXES):
            _position_panel(cols[0][r], runs, r, t_range, cg=False)
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


__all__ = ["KINDS", "STYLE", "virtual_point_track", "lever_arm", "steady_start", "total_variation_rate",
           "fig_trajectory3d", "fig_positions", "fig_velocities", "fig_inputs",
           "fig_errors", "fig_chi", "fig_overview", "plot_runs", "save_figure", "normalize_runs", "run_label"]
