"""Result: access, pandas, run-folder round trip (CSV, JSON, MAT) and plots, on synthetic data."""
from __future__ import annotations

import hashlib
import json
import math
import tomllib

import numpy as np
import pytest
from matplotlib.figure import Figure
from scipy.io import loadmat

import auvtrack
from auvtrack.metrics import METRIC_NAMES, metrics_from_trajectory
from auvtrack.simulation.plotting import KINDS, plot_runs, save_figure
from auvtrack.simulation.result import BASE_CHANNELS, Result, restore_nonfinite, to_jsonable

EXTRA = tuple(f"{n}_{a}" for n in ("rho", "rho1", "chi_hat", "sliding") for a in "xyz") + ("chi_x", "chi_y", "chi_z")


def make_result(n=401, dt=0.05, extras=True, status="ok", kind="fxtntsmc", seed=0):
    """A synthetic, physically plausible run (helix reference, decaying error)."""
    rng = np.random.default_rng(seed)
    t = np.arange(n) * dt
    ch = {name: np.zeros(n) for name in BASE_CHANNELS}
    ch["t"] = t
    ch["xd"], ch["yd"], ch["zd"] = 4 * np.cos(0.1 * t), 4 * np.sin(0.1 * t), -0.1 * t
    for i, a in enumerate("xyz"):
        ch[f"e{a}"] = (0.5 - 0.3 * i) * np.exp(-t / 3) + 1e-3 * rng.normal(size=n)
        ch[a] = ch[f"{a}d"] + ch[f"e{a}"]
    for name in ("theta", "psi", "u", "v", "w", "q", "r"):
        ch[name] = 0.1 * np.sin(t + rng.uniform())
    ch["tau_u"], ch["tau_q"], ch["tau_r"] = 50 * np.exp(-t), np.cos(3 * t), np.sin(2 * t)
    if extras:
        for a in "xyz":
            ch[f"rho_{a}"] = 5 * np.exp(-t / 2) + 0.005
        for a in "xyz":
            ch[f"rho1_{a}"] = 4 * np.exp(-t / 2) + 0.005
        for a in "xyz":
            ch[f"chi_hat_{a}"] = np.cos(t) * (1 - np.exp(-t))
        for a in "xyz":
            ch[f"sliding_{a}"] = np.exp(-t)
        for a in "xyz":
            ch[f"chi_{a}"] = np.cos(t)
    e = np.column_stack([ch["ex"], ch["ey"], ch["ez"]])
    tau = np.column_stack([ch["tau_u"], ch["tau_q"], ch["tau_r"]])
    metrics = metrics_from_trajectory(t, e, tau)
    failure = None
    if status == "failed":
        failure = {"time": float(t[-1]), "cause": "pitch_limit", "detail": "pitch limit exceeded",
                   "state": {"theta": np.float64(1.55), "u": 0.2, "controller_state": [0.1, np.nan]}}
    scenario = {"name": "synthetic", "seed": 3, "controller": {"kind": kind, "gains": [0.005, 0.8, 0.6]},
                "sim": {"dt": dt, "duration": float(t[-1])}, "metrics": {"window": [0.0, math.inf]}}
    meta = {"wall_time_s": np.float64(0.25), "steps": np.int64(n - 1), "notes": ["widened envelope"],
            "flag": np.bool_(True), "ratio": np.float32(0.5)}
    return Result(ch, scenario, status, failure, metrics, meta)


def bits(a):
    return np.asarray(a, dtype=np.float64).view(np.uint64)


def eq_nan(a, b):
    """Deep equality where NaN equals NaN."""
    if isinstance(a, dict):
        return isinstance(b, dict) and a.keys() == b.keys() and all(eq_nan(a[k], b[k]) for k in a)
    if isinstance(a, (list, tuple)):
        return isinstance(b, (list, tuple)) and len(a) == len(b) and all(eq_nan(x, y) for x, y in zip(a, b))
    if isinstance(a, float) and isinstance(b, float) and math.isnan(a) and math.isnan(b):
        return True
    return a == b


# ------------------------------------------------------------------ construction and access
def test_access_and_repr():
    res = make_result()
    assert res.names[:len(BASE_CHANNELS)] == BASE_CHANNELS
    assert res.names[-3:] == ("chi_x", "chi_y", "chi_z")
    assert res.t is res["t"] and len(res) == 401
    assert "rho_x" in res and "nope" not in res
    assert list(res) == list(res.names)
    assert res.ok and res.duration == pytest.approx(20.0)
    with pytest.raises(KeyError, match="no channel"):
        res["nope"]
    with pytest.raises(ValueError):
        res["x"][0] = 1.0  # read-only record
    text = repr(res)
    assert "status='ok'" in text and "fxtntsmc" in text and "rmse" in text
    failed = make_result(status="failed")
    assert not failed.ok and "pitch_limit" in repr(failed)
    assert list(res.metrics) == list(METRIC_NAMES)


def test_constructor_validation():
    good = make_result(extras=False)
    ch = good.channels
    with pytest.raises(ValueError, match="start with"):
        Result({k: ch[k] for k in reversed(list(ch))}, {}, "ok", None, {})
    with pytest.raises(ValueError, match="samples"):
        Result({**ch, "extra": np.zeros(3)}, {}, "ok", None, {})
    with pytest.raises(ValueError, match="1-D"):
        Result({**ch, "extra": np.zeros((len(good), 2))}, {}, "ok", None, {})
    with pytest.raises(ValueError, match="invalid channel name"):
        Result({**ch, "bad,name": np.zeros(len(good))}, {}, "ok", None, {})
    with pytest.raises(ValueError, match="status"):
        Result(ch, {}, "crashed", None, {})
    with pytest.raises(ValueError, match="failure"):
        Result(ch, {}, "failed", None, {})
    with pytest.raises(ValueError, match="failure"):
        Result(ch, {}, "ok", {"time": 1.0, "cause": "x", "detail": "y", "state": {}}, {})
    with pytest.raises(ValueError, match="lacks"):
        Result(ch, {}, "failed", {"time": 1.0}, {})


def test_to_pandas():
    res = make_result()
    df = res.to_pandas()
    assert list(df.columns) == list(res.names)
    assert df.shape == (len(res), len(res.names))
    np.testing.assert_array_equal(df["ex"].to_numpy(), res["ex"])
    df.loc[0, "x"] = 123.0  # the frame is a copy
    assert res["x"][0] != 123.0


def test_top_level_export():
    assert auvtrack.Result is Result


# ------------------------------------------------------------------ run folder
def test_save_load_round_trip(tmp_path):
    res = make_result()
    folder = res.save(tmp_path / "a" / "run")
    assert folder == tmp_path / "a" / "run"
    assert sorted(p.name for p in folder.iterdir()) == ["run.json", "scenario.toml", "trajectory.csv"]
    assert tomllib.loads((folder / "scenario.toml").read_text()) == res.scenario  # inf written as TOML inf
    back = Result.load(folder)
    assert back.names == res.names
    for name in res.names:
        np.testing.assert_array_equal(bits(back[name]), bits(res[name]))
    assert back.scenario == res.scenario  # window [0, inf] restored
    assert eq_nan(back.metrics, res.metrics)
    assert back.metrics["settle_1mm_x"] == res.metrics["settle_1mm_x"]
    assert back.status == "ok" and back.failure is None
    assert back.meta == {"wall_time_s": 0.25, "steps": 400, "notes": ["widened envelope"], "flag": True,
                         "ratio": 0.5}
    assert back.version == auvtrack.__version__


def test_special_values_round_trip_bit_exact(tmp_path):
    res = make_result(n=8, extras=False)
    ch = res.channels
    ch["u"] = np.array([np.nan, np.inf, -np.inf, -0.0, 5e-324, 1.7976931348623157e308, 0.1, 1 / 3])
    special = Result(ch, {}, "ok", None, {})
    back = Result.load(special.save(tmp_path))
    np.testing.assert_array_equal(bits(back["u"]), bits(special["u"]))


def test_csv_header_and_bytes(tmp_path):
    res = make_result()
    res.save(tmp_path / "one")
    make_result().save(tmp_path / "two")
    text = (tmp_path / "one" / "trajectory.csv").read_text()
    lines = text.splitlines()
    assert lines[0] == ",".join(BASE_CHANNELS + EXTRA)
    assert len(lines) == len(res) + 1 and text.endswith("\n")
    assert lines[1].split(",")[0] == "0.0"
    assert (tmp_path / "one" / "trajectory.csv").read_bytes() == (tmp_path / "two" / "trajectory.csv").read_bytes()
    assert (tmp_path / "one" / "run.json").read_bytes() == (tmp_path / "two" / "run.json").read_bytes()
    import pandas as pd

    df = pd.read_csv(tmp_path / "one" / "trajectory.csv")
    assert list(df.columns) == list(res.names)
    np.testing.assert_array_equal(df["ey"].to_numpy(), res["ey"])


def test_csv_is_streamed_in_blocks_with_the_same_bytes(tmp_path):
    """The block-wise writer gives exactly the text of each whole column formatted at once, across block edges."""
    from auvtrack.simulation.result import CSV_BLOCK_ROWS, csv_column

    res = make_result(n=2 * CSV_BLOCK_ROWS + 17, extras=False)
    cols = [[str(x) for x in csv_column(v).cast("string").to_pylist()] for v in res.channels.values()]
    expected = ",".join(res.names) + "\n" + "".join(",".join(r) + "\n" for r in zip(*cols))
    assert (res.save(tmp_path / "big") / "trajectory.csv").read_text() == expected
    assert Result(res.channels, {}, "ok", None, {}).save(tmp_path / "empty-scenario").joinpath(
        "scenario.toml").exists() is False  # no scenario, no scenario.toml


def test_json_is_strict_and_converted(tmp_path):
    res = make_result(status="failed")
    res.save(tmp_path)
    raw = (tmp_path / "run.json").read_text()

    def no_constants(name):
        raise AssertionError(f"non-standard JSON constant {name}")

    doc = json.loads(raw, parse_constant=no_constants)
    assert list(doc) == ["version", "status", "failure", "metrics", "scenario", "meta", "nonfinite", "files"]
    for name in ("trajectory.csv", "scenario.toml"):
        data = (tmp_path / name).read_bytes()
        assert doc["files"][name] == {"sha256": hashlib.sha256(data).hexdigest(), "bytes": len(data)}
    assert doc["version"] == auvtrack.__version__
    assert doc["metrics"]["settle_1mm_x"] is None  # inf -> null
    assert doc["nonfinite"]["/metrics/settle_1mm_x"] == "inf"
    assert doc["scenario"]["metrics"]["window"] == [0.0, None]
    assert doc["nonfinite"]["/scenario/metrics/window/1"] == "inf"
    assert doc["failure"]["state"]["controller_state"] == [0.1, None]
    assert doc["nonfinite"]["/failure/state/controller_state/1"] == "nan"
    assert doc["meta"]["steps"] == 400 and isinstance(doc["meta"]["flag"], bool)
    assert set(doc["metrics"]) == set(METRIC_NAMES)


def test_failed_result_round_trip(tmp_path):
    res = make_result(status="failed")
    back = Result.load(res.save(tmp_path / "failed", mat=True))
    assert back.status == "failed" and not back.ok
    assert eq_nan(back.failure, {"time": 20.0, "cause": "pitch_limit", "detail": "pitch limit exceeded",
                                 "state": {"theta": 1.55, "u": 0.2, "controller_state": [0.1, math.nan]}})


def test_empty_result_round_trip(tmp_path):
    ch = {name: np.zeros(0) for name in BASE_CHANNELS}
    failure = {"time": 0.0, "cause": "controller", "detail": "singular", "state": {}}
    res = Result(ch, {"name": "x"}, "failed", failure, {n: math.nan for n in METRIC_NAMES})
    assert "no samples" in repr(res)
    back = Result.load(res.save(tmp_path))
    assert back.names == BASE_CHANNELS and len(back) == 0
    assert all(math.isnan(v) for v in back.metrics.values())


def test_mat_file(tmp_path):
    res = make_result()
    folder = res.save(tmp_path, mat=True)
    m = loadmat(folder / "trajectory.mat")
    for name in res.names:
        assert m[name].shape == (len(res), 1)
        np.testing.assert_array_equal(m[name][:, 0], res[name])
    assert [str(c[0]) for c in m["channel_names"].ravel()] == list(res.names)
    assert json.loads(str(m["scenario_json"][0]))["controller"]["kind"] == "fxtntsmc"
    assert str(m["status"][0]) == "ok"
    metrics = m["metrics"][0, 0]
    assert set(metrics.dtype.names) == set(METRIC_NAMES)
    assert float(metrics["rmse_x"].squeeze()) == res.metrics["rmse_x"]
    assert math.isinf(float(metrics["settle_1mm_x"].squeeze()))
    # saving again without mat removes the stale file
    res.save(tmp_path)
    assert not (tmp_path / "trajectory.mat").exists()


def test_json_helpers():
    nf: dict = {}
    doc = to_jsonable({"a/b": [1.0, np.float32(np.inf)], "c": (np.int64(2), -math.inf), "d": np.arange(2)}, nf)
    assert doc == {"a/b": [1.0, None], "c": [2, None], "d": [0, 1]}
    assert nf == {"/a~1b/1": "inf", "/c/1": "-inf"}
    assert restore_nonfinite(json.loads(json.dumps(doc)), nf) == {"a/b": [1.0, math.inf], "c": [2, -math.inf],
                                                                  "d": [0, 1]}


# ------------------------------------------------------------------ plots
N_AXES = {"trajectory3d": 1, "positions": 3, "velocities": 5, "inputs": 6, "errors": 8, "chi": 3, "overview": 10}


@pytest.mark.parametrize("kind", KINDS)
@pytest.mark.parametrize("extras", [True, False])
def test_plot_kinds(kind, extras):
    res = make_result(extras=extras)
    fig = res.plot(kind)
    assert isinstance(fig, Figure)
    assert len(fig.axes) == N_AXES[kind]
    for ax in fig.axes:
        assert ax.get_ylabel() or ax.name == "3d"


def test_plot_labels_and_envelopes():
    res = make_result()
    fig = res.plot("errors")
    ax = fig.axes[0]
    assert ax.get_ylabel() == "$e_x$ (m)" and fig.axes[-1].get_xlabel() == "t (s)"
    styles = [line.get_linestyle() for line in ax.get_lines()]
    assert styles.count("-.") == 2 and styles.count("--") == 2  # ±rho and ±rho1
    labels = [t.get_text() for t in fig.legends[0].get_texts()]
    assert "fxtntsmc" in labels and any("baseline" in lab for lab in labels)
    assert len(res.plot("positions").axes[0].get_lines()) == 3  # reference, virtual point, CG
    assert len(res.plot("positions", cg=False).axes[0].get_lines()) == 2
    texts = [t.get_text() for t in res.plot("positions", label="mine").legends[0].get_texts()]
    assert texts[0].startswith("reference") and texts[1].startswith("mine: virtual point")
    assert len(res.plot("inputs", steady_from=None).axes) == 3
    assert len(res.plot("errors", envelopes=False).axes) == 3


def test_comparison_and_save_figure(tmp_path):
    runs = [("FXTNTSMC", make_result()), ("FTSMC", make_result(extras=False, kind="ftsmc", seed=1))]
    fig = plot_runs("positions", runs)
    assert len(fig.axes[0].get_lines()) == 5  # reference + (virtual point, CG) per run
    fig = plot_runs("chi", dict(runs))
    assert len(fig.axes[0].get_lines()) == 1  # only the run with chi_hat
    written = save_figure(plot_runs("overview", runs), tmp_path / "figs" / "fig3")
    assert [p.name for p in written] == ["fig3.png", "fig3.pdf"]
    assert all(p.stat().st_size > 0 for p in written)
    with pytest.raises(ValueError, match="unknown plot kind"):
        plot_runs("bogus", runs)
    with pytest.raises(ValueError):
        plot_runs("positions", [])


def test_plot_empty_result_does_not_raise():
    ch = {name: np.zeros(0) for name in BASE_CHANNELS}
    res = Result(ch, {}, "failed", {"time": 0.0, "cause": "c", "detail": "d", "state": {}}, {})
    for kind in KINDS:
        assert isinstance(res.plot(kind), Figure)
