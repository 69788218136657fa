"""A learned policy (``controller.kind = "policy"``) in a sweep: every row is that policy flown.

The rows of a sweep chunk (the batch runner's back end for a worker: the SIMD lanes where the
vector math library is in use) equal a direct run of each sample bit for bit, two policy files
give two different sets of rows, and the kernels the local cluster's client compiles before the
workers start include the policy's.
"""
from __future__ import annotations

import textwrap

import numpy as np
import pyarrow as pa

from auvtrack.batch.sweep import study_kernels
from auvtrack.batch.sweep_spec import load_study
from auvtrack.batch.sweep_worker import run_chunk
from auvtrack.control.policy import OBS, policy_path, save_policy
from auvtrack.metrics import METRIC_NAMES
from auvtrack.scenario import load_scenario
from auvtrack.simulation.compiling import lane_note
from auvtrack.simulation.pipeline import prepare, run_prepared

STUDY = """
name = "policy-sweep"
scenario = "paper"
set = ["sim.duration=0.4", "metrics.window=[0.0, 0.4]"]
seed = 5
samples = 2
chunk_size = 3
common_seeds = true               # both files flown on the same draws

[grid]
"controller.kind" = ["policy"]
"controller.file" = ["remus100-cmaes", "{other}"]

[random."uncertainty.D"]
dist = "uniform"
low = 0.0
high = 0.3
"""


def _other_policy(path):
    rng = np.random.default_rng(11)
    dims = [OBS.size, 8, 3]
    ws = [rng.normal(0, 1 / np.sqrt(dims[i]), (dims[i + 1], dims[i])) for i in range(2)]
    bs = [rng.normal(0, 0.1, dims[i + 1]) for i in range(2)]
    return save_policy(path, ws, bs, ("tanh", "identity"), (40.0, 10.0, 10.0))


def test_sweep_rows_are_the_policy_flown(tmp_path):
    other = _other_policy(tmp_path / "other.npz")
    study = tmp_path / "study.toml"
    study.write_text(textwrap.dedent(STUDY).replace("{other}", str(other)))
    spec = load_study(study)
    df = pa.concat_tables([run_chunk(spec, c) for c in range(spec.n_chunks)]).to_pandas()
    assert len(df) == 4 and (df["status"] == "ok").all()
    direct = []
    for i in range(4):
        prep = prepare(load_scenario(spec.base, spec.overrides(i)[1]))
        assert prep.key.law == "auvtrack.control.policy" and lane_note(prep.key) is None  # SIMD lanes, no fallback
        res = run_prepared(prep)
        direct.append([res.metrics[m] for m in METRIC_NAMES])
        np.testing.assert_array_equal(df.loc[i, list(METRIC_NAMES)].to_numpy(float), np.array(direct[-1]))
    # the file is flown: the shipped policy's rows and the other policy's rows differ on the same draws
    shipped, mine = np.array(direct[:2]), np.array(direct[2:])
    assert spec.sample(0)[2]["uncertainty.D"] == spec.sample(2)[2]["uncertainty.D"]  # common random numbers
    assert np.all(np.abs(shipped[:, 0] - mine[:, 0]) > 1e-6)
    # and it is not the scenario's own controller: the paper's FXTNTSMC flies other numbers
    own = {k: v for k, v in spec.overrides(0)[1].items() if not k.startswith("controller.")}
    base = run_prepared(prepare(load_scenario(spec.base, own)))
    assert prepare(load_scenario(spec.base, own)).key.law != "auvtrack.control.policy"
    assert base.metrics[METRIC_NAMES[0]] != direct[0][0]


def test_the_client_compiles_the_policy_kernel_before_the_workers(tmp_path):
    other = _other_policy(tmp_path / "other.npz")
    study = tmp_path / "study.toml"
    study.write_text(textwrap.dedent(STUDY).replace("{other}", str(other)))
    preps = study_kernels(load_study(study))
    assert len(preps) == 2  # one per policy file (one kernel: the same law on the same plant)
    assert {p.key.law for p in preps} == {"auvtrack.control.policy"}
    files = {p.scenario.controller.file for p in preps}
    assert files == {"remus100-cmaes", str(other)} and policy_path("remus100-cmaes").is_file()
