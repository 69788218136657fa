"""The paper's figures show what the claims are about: inspected through their Axes.

* Figures 3 and 4 plot the virtual point eta1 (what the controllers track) against eta_d, the
  centre of gravity only as a thin labelled line; every run's start marker stays visible.
* Figure 6 has a steady-state column on its own scale, smoothest line on top.
* Figure 7 adds |e| with the envelope on a log scale, |e|/rho and the flexible part rho_bar.
"""
from __future__ import annotations

import numpy as np
import pytest

import auvtrack
from auvtrack.simulation import plotting
from auvtrack.simulation.result import Result

from test_result import make_result


@pytest.fixture(scope="module")
def section4():
    """Two seconds of Section 4 for both controllers (the real channels, the real lever arm)."""
    return [(label, auvtrack.simulate("scenarios/paper.toml", [f"controller.kind={kind}", "sim.duration=2"],
                                      warn=False))
            for label, kind in (("FXTNTSMC", "fxtntsmc"), ("FTSMC", "ftsmc"))]


def _line(ax, label):
    found = [ln for ln in ax.get_lines() if ln.get_label() == label]
    assert len(found) == 1, (label, [ln.get_label() for ln in ax.get_lines()])
    return found[0]


def test_virtual_point_is_the_kinematic_point_ell_ahead_of_the_cg(section4):
    for _, res in section4:
        ell = plotting.lever_arm(res)
        assert ell == 1.0
        th, ps = res["theta"], res["psi"]
        kin = np.column_stack([res["x"] + ell * np.cos(th) * np.cos(ps), res["y"] + ell * np.cos(th) * np.sin(ps),
                               res["z"] - ell * np.sin(th)])  # paper eq. (2)
        vp = plotting.virtual_point_track(res)
        np.testing.assert_allclose(vp, kin, rtol=0, atol=1e-12)
        # the CG is visibly elsewhere: the figure must not pass it off as the tracked point
        assert np.abs(kin[:, 0] - res["x"]).max() > 0.5


def test_fig4_plots_the_virtual_point_against_the_reference(section4):
    fig = plotting.fig_positions(section4)
    vp = {label: plotting.virtual_point_track(res) for label, res in section4}
    res0 = section4[0][1]
    for i, (ax, a) in enumerate(zip(fig.axes, "xyz")):
        ref = _line(ax, r"reference $\eta_d$")
        np.testing.assert_array_equal(ref.get_ydata(), res0[f"{a}d"])
        for k, (label, res) in enumerate(section4):
            line = _line(ax, f"{label}: virtual point $\\eta_1$")
            np.testing.assert_array_equal(line.get_ydata(), vp[label][:, i])
            cg = _line(ax, f"{label}: CG")
            np.testing.assert_array_equal(cg.get_ydata(), res[a])
            assert cg.get_linewidth() < line.get_linewidth()  # the CG is the thin line
            assert cg.get_color() == line.get_color()
        assert ref.get_zorder() > max(ln.get_zorder() for ln in ax.get_lines() if ln is not ref)
    assert "virtual point" in fig.get_suptitle() and "1 m ahead of the CG" in fig.get_suptitle()
    assert fig.axes[2].get_ylabel() == "z (m, positive down)"


def test_fig3_draws_virtual_points_and_distinct_visible_start_markers(section4):
    fig = plotting.fig_trajectory3d(section4)
    (ax,) = fig.axes
    for label, res in section4:
        xs, ys, zs = _line(ax, f"{label}: virtual point $\\eta_1$").get_data_3d()
        np.testing.assert_array_equal(np.column_stack([xs, ys, zs]), plotting.virtual_point_track(res))
        _line(ax, f"{label}: CG")
    starts = [c for c in ax.collections if c.get_label().endswith(": start")]
    assert [c.get_label() for c in starts] == ["FXTNTSMC: start", "FTSMC: start"]
    # same start point: hollow markers of different shapes and sizes, so neither hides the other
    assert all(len(c.get_facecolor()) == 0 or c.get_facecolor()[0][3] == 0 for c in starts)
    assert starts[0].get_sizes()[0] > starts[1].get_sizes()[0]
    assert len({c.get_paths()[0].vertices.shape for c in starts}) == 2
    assert ax.zaxis_inverted()  # NED: down is down
    assert not plotting.fig_trajectory3d(section4, cg=False).axes[0].get_lines()[0].get_label().endswith("CG")


def _chattering_pair():
    """A smooth and a chattering run with start-up spikes far above the steady-state inputs."""
    smooth, chatter = make_result(extras=False), make_result(extras=False, kind="ftsmc", seed=1)
    t = smooth.t
    spike = 1000.0 * np.exp(-5 * t)
    ch_s, ch_c = smooth.channels, chatter.channels
    for j, name in enumerate(("tau_u", "tau_q", "tau_r")):
        ch_s[name] = spike + 40.0 + np.sin(0.5 * t + j)
        ch_c[name] = 0.5 * spike + 40.0 + np.sin(0.5 * t + j) + 8.0 * np.sign(np.sin(40 * t))
    mk = lambda ch, r: Result(ch, r.scenario, "ok", None, r.metrics)  # noqa: E731
    return [("smooth", mk(ch_s, smooth)), ("chatter", mk(ch_c, chatter))]


def test_fig6_has_a_steady_state_column_with_the_smoothest_line_on_top():
    runs = _chattering_pair()
    fig = plotting.fig_inputs(runs, steady_from=10.0)
    assert len(fig.axes) == 6
    left, right = fig.axes[0::2], fig.axes[1::2]
    assert "steady state, t ≥ 10 s" in right[0].get_title()
    for a_full, a_ss in zip(left, right):
        assert a_ss.get_ylabel() == a_full.get_ylabel()
        for line in a_ss.get_lines():
            assert line.get_xdata().min() >= 10.0
        # its own scale: the start-up spike (~1000) no longer sets it
        assert np.ptp(a_ss.get_ylim()) < 0.1 * np.ptp(a_full.get_ylim())
        for ax in (a_full, a_ss):
            top = max(ax.get_lines(), key=lambda ln: ln.get_zorder())
            assert top.get_label() == "smooth"
    assert [t.get_text() for t in left[0].get_legend().get_texts()] == ["smooth", "chatter"]  # in run order
    # a run shorter than steady_from: the second half of the run, said in the title
    assert plotting.steady_start(runs, 100.0) == pytest.approx(10.0)
    assert len(plotting.fig_inputs(runs, steady_from=None).axes) == 3


def test_total_variation_rate_of_a_known_signal():
    t = np.linspace(0.0, 2.0, 2001)
    assert plotting.total_variation_rate(t, np.sin(2 * np.pi * t)) == pytest.approx(4.0, rel=1e-5)  # 4 A f, A = f = 1
    assert plotting.total_variation_rate(t[:1], t[:1]) == 0.0


def test_fig7_shows_the_envelope_at_every_scale(section4):
    fig = plotting.fig_errors(section4)
    assert len(fig.axes) == 8
    grid = np.array(fig.axes).reshape(4, 2)
    fx = section4[0][1]
    for r, a in enumerate("xyz"):
        assert grid[r, 1].get_yscale() == "log"
        line = _line(grid[r, 1], "_FXTNTSMC")
        np.testing.assert_array_equal(line.get_ydata(), np.abs(fx[f"e{a}"]))
        np.testing.assert_array_equal(_line(grid[r, 1], "_rho FXTNTSMC").get_ydata(), fx[f"rho_{a}"])
    ratio, widening = grid[3, 0], grid[3, 1]
    assert ratio.get_yscale() == "log" and "rho_i" in ratio.get_ylabel()
    for a in "xyz":
        np.testing.assert_array_equal(_line(ratio, f"_FXTNTSMC {a}").get_ydata(),
                                      np.abs(fx[f"e{a}"]) / fx[f"rho_{a}"])
        np.testing.assert_array_equal(_line(widening, f"_FXTNTSMC {a}").get_ydata(), fx[f"rho_{a}"] - fx[f"rho1_{a}"])
    assert not [ln for ln in ratio.get_lines() if ln.get_label().startswith("_FTSMC")]  # no envelope, no ratio
    boundary = _line(ratio, "_boundary")
    assert set(boundary.get_ydata()) == {1.0}
    peak = max(np.max(np.abs(fx[f"e{a}"]) / fx[f"rho_{a}"]) for a in "xyz")
    assert peak < 1.0 and f"{peak:.2g}" in ratio.get_title()  # inside the envelope, and the title says by how much
    # Section 4 widens the y envelope at the start (ERRATA 9): rho_bar_y(0) > 0, the others 0
    assert fx["rho_y"][0] - fx["rho1_y"][0] > 0 and fx["rho_x"][0] == fx["rho1_x"][0]


def test_fig7_without_any_envelope_says_so():
    res = make_result(extras=False, kind="ftsmc")
    fig = plotting.fig_errors(res)
    texts = [t.get_text() for ax in fig.axes for t in ax.texts]
    assert "no run logs an envelope" in texts and "no run logs a flexible envelope" in texts
    nan_env = make_result()
    ch = nan_env.channels
    for a in "xyz":  # envelope.kind = "none" logs NaN envelopes
        ch[f"rho_{a}"] = np.full(len(nan_env), np.nan)
    res = Result(ch, nan_env.scenario, "ok", None, nan_env.metrics)
    assert "no run logs an envelope" in [t.get_text() for t in plotting.fig_errors(res).axes[6].texts]
