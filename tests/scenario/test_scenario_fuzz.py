"""Property tests of scenario validation: every malformation is a one-line ScenarioError naming
the mutated field, every in-range scenario loads and round-trips."""
from __future__ import annotations

import copy
import math
import warnings
from pathlib import Path

from hypothesis import event, given, settings
from hypothesis import strategies as st

from auvtrack.control import CONTROLLERS
from auvtrack.plant import get as get_plant
from auvtrack.scenario import ScenarioError, load_scenario
from auvtrack.simulation.pipeline import prepare
from doc_ranges import documented_ranges

PAPER = Path(__file__).resolve().parents[2] / "scenarios" / "paper.toml"
BASE = load_scenario(PAPER).to_dict()  # valid, every leaf spelled out
FUZZ = settings(max_examples=200, deadline=None)
INF = math.inf


# --- walking the base dict ----------------------------------------------------------------------

def _walk(d, prefix=()):
    """Yield (path, value) for every table, list and scalar below ``d``."""
    yield prefix, d
    items = d.items() if isinstance(d, dict) else enumerate(d) if isinstance(d, list) else ()
    for k, v in items:
        yield from _walk(v, prefix + (k,))


NODES = list(_walk(BASE))
TABLES = [p for p, v in NODES if isinstance(v, dict)]
SCALARS = [p for p, v in NODES if not isinstance(v, (dict, list))]
NUMBER_LISTS = [p for p, v in NODES if isinstance(v, list) and v and not isinstance(v[0], (dict, list))]


def dotted(path) -> str:
    return ".".join(str(s) for s in path)


def field_path(path) -> str:
    """The field a mutation belongs to: the list for a list element, else the leaf itself."""
    parent = path[:-1]
    return dotted(parent) if parent in NUMBER_LISTS else dotted(path)


def mutate(path, value, base=None) -> dict:
    data = copy.deepcopy(BASE if base is None else base)
    node = data
    for seg in path[:-1]:
        node = node[seg]
    node[path[-1]] = value
    return data


def validate(data) -> str | None:
    """The validation of ``auvtrack check`` / ``run`` (load, plan, controller set-up) on a dict:
    None when accepted, else the one-line message (``<dict>: `` in front, as the CLI puts the file)."""
    try:
        sc = load_scenario(data)
    except ScenarioError as exc:
        return str(exc)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            prepare(sc)
    except ValueError as exc:
        return f"<dict>: {exc}"
    return None


def names(msg: str, path: str) -> bool:
    body = msg[len("<dict>: "):]
    return body.startswith(path) and body[len(path):len(path) + 1] in (".", ":")


def assert_error_names(data, path: str) -> None:
    msg = validate(data)
    if msg is None:
        raise AssertionError(f"no error for a malformed {path}")
    assert "\n" not in msg and "\r" not in msg, msg
    assert msg.startswith("<dict>: "), msg
    assert names(msg, path), (path, msg)


# --- forbidden ranges, read from the documented table (docs/scenarios.md), never from the schema -

# every registered controller's rows of the [controller] table are checked on the paper scenario
# (a controller that cannot fly the paper's 5-DOF plant, e.g. one commanding fins and propeller, on the 6-DOF one)
_NEEDS = {"plugin": [f'controller.module="{Path(__file__).resolve().parents[2] / "examples" / "plugin_controller.py"}"']}


def _base(kind: str) -> dict:
    plant = [] if CONTROLLERS[kind].runs_on(get_plant("5dof")) else ["plant.model=6dof"]
    return load_scenario(PAPER, [f"controller.kind={kind}", *plant, *_NEEDS.get(kind, [])]).to_dict()


BASES = {"": BASE, **{kind: _base(kind) for kind in CONTROLLERS}}
DOCUMENTED = [(rng, BASES.get(kind)) for kind, rngs in documented_ranges(BASE).items() for rng in rngs
              if kind in BASES]


def test_the_documented_table_is_parsed():
    """The parser finds the ranges the tests rely on (a table edit that breaks it fails here)."""
    by_path = {r.dotted: r for r, _ in DOCUMENTED}
    for path in ("sim.dt", "sim.theta_limit", "vehicle.m.0", "vehicle.l", "initial.nu.3", "envelope.xi0",
                 "estimator.neurons", "controller.a2", "controller.gamma", "limits.max_steps", "seed"):
        assert path in by_path, path
    assert by_path["sim.dt"].hi == 0.1 and not by_path["sim.dt"].hi_open
    assert by_path["estimator.neurons"].integer and by_path["seed"].integer
    assert len(DOCUMENTED) > 80


def below(x: float) -> float:
    """Largest float < x (explicit: hypothesis may turn ``x < 0`` filters into -0.0)."""
    return math.nextafter(float(x), -INF)


def above(x: float) -> float:
    """Smallest float > x."""
    return math.nextafter(float(x), INF)


def _outside(r):
    """Values outside the documented range ``r``."""
    parts = []
    if r.integer:
        if r.lo is not None:
            parts.append(st.integers(max_value=int(r.lo) - (0 if r.lo_open else 1)))
        if r.hi is not None:
            parts.append(st.integers(min_value=int(r.hi) + (0 if r.hi_open else 1)))
        return st.one_of(parts)
    if r.lo is not None:
        parts.append(st.floats(max_value=r.lo if r.lo_open else below(r.lo), allow_nan=False))
    if r.hi is not None:
        parts.append(st.floats(min_value=r.hi if r.hi_open else above(r.hi), allow_nan=False))
    return st.one_of(parts)


def _boundaries(r) -> list:
    """The documented range's own edges, from inside (closed ends exactly, open ends one ulp in)."""
    out = []
    for edge, is_open, inward in ((r.lo, r.lo_open, INF), (r.hi, r.hi_open, -INF)):
        if edge is None:
            continue
        if r.integer:
            out.append(int(edge) + (0 if not is_open else (1 if inward > 0 else -1)))
        else:
            out.append(math.nextafter(float(edge), inward) if is_open else float(edge))
    return out


def _not_multiple(step: float, kmin: int):
    return st.builds(lambda k, f: (k + f) * step, st.integers(kmin, 10_000), st.floats(0.01, 0.99))


dt = BASE["sim"]["dt"]
CROSS = [
    (("sim", "log_dt"), st.floats(0, dt, exclude_min=True, exclude_max=True)),
    (("sim", "log_dt"), _not_multiple(dt, 1)),
    # a multiple of dt that does not divide the duration (100 s): the log would stop early
    (("sim", "log_dt"), st.sampled_from([0.003, 0.007, 0.03, 0.3, 3.0, 7.0, 30.0, 150.0, 1e4])),
    (("sim", "duration"), _not_multiple(dt, 1)),
    (("sim", "control_rate"), _not_multiple(dt, 1).map(lambda p: 1.0 / p)),
    (("sim", "control_rate"), st.floats(1e-300, below(1.0 / BASE["sim"]["duration"]))),
    (("initial", "eta", 3), st.floats(math.pi / 2, allow_nan=False) | st.floats(max_value=-math.pi / 2)),
    (("initial", "eta", 3), st.floats(math.radians(BASE["sim"]["theta_limit"]), below(math.pi / 2))),
    (("metrics", "window", 0), st.floats(max_value=below(0.0), allow_nan=False)),
    (("metrics", "window", 1), st.floats(max_value=BASE["metrics"]["window"][0], allow_nan=False)),
    (("estimator", "centre_range", 1), st.floats(max_value=BASE["estimator"]["centre_range"][0])),
    (("estimator", "weight_range", 1),
     st.floats(max_value=below(BASE["estimator"]["weight_range"][0]))),
    # ranges owned by the reference / disturbance modules (their docstrings)
    (("reference", "radius"), st.floats(max_value=0) | st.floats(min_value=1e6)),
    (("reference", "omega"), st.floats(min_value=100, exclude_min=True) | st.floats(max_value=-100, exclude_max=True)),
    (("reference", "climb"), st.floats(min_value=1000, exclude_min=True)),
    (("disturbance", 0, "amplitude"), st.floats(max_value=below(0.0))),
] + [(("envelope", "rho_inf", i), st.floats(min_value=r, allow_nan=False))
     for i, r in enumerate(BASE["envelope"]["rho0"])]


def _get(path, base=None):
    node = BASE if base is None else base
    for seg in path:
        node = node[seg]
    return node


# every number must be finite (metrics.window[1] alone may be inf)
NON_FINITE = [(p, st.sampled_from([INF, -INF, math.nan])) for p in SCALARS
              if isinstance(_get(p), float) and p != ("metrics", "window", 1)]
OUT_OF_RANGE = ([(r.path, _outside(r), base) for r, base in DOCUMENTED]
                + [(p, strat, BASE) for p, strat in CROSS + NON_FINITE])


# --- wrong types --------------------------------------------------------------------------------

BROADCAST = {("envelope", "rho0"), ("envelope", "rho_inf"), ("actuator", "tau_max"), ("actuator", "rate_max")}


def _wrong_type(path):
    value = _get(path)
    if path in NUMBER_LISTS:
        options = ["abc", {"a": 1}] + ([] if path in BROADCAST else [2.5])
    elif isinstance(value, bool):
        options = ["yes", 1.5, 1, [True], {"a": 1}]
    elif isinstance(value, int):
        options = ["abc", "1", 1.5, True, [1], {"a": 1}]
    elif isinstance(value, float) or value == "inf":  # to_dict writes inf as "inf"
        options = ["abc", "1.0", True, [1.0], {"a": 1}]
    else:  # str
        options = [3.5, True, [1, 2], {"a": 1}]
    return st.sampled_from(options)


WRONG_TYPE_PATHS = SCALARS + NUMBER_LISTS


# --- properties: malformed input ---------------------------------------------------------------

@FUZZ
@given(data=st.data())
def test_unknown_key_is_named(data):
    table = data.draw(st.sampled_from(TABLES), label="table")
    key = data.draw(st.from_regex(r"\Azz_[a-z0-9_]{0,8}\Z"), label="key")
    value = data.draw(st.integers() | st.text(max_size=5) | st.booleans(), label="value")
    assert_error_names(mutate(table + (key,), value), dotted(table + (key,)))


@FUZZ
@given(data=st.data())
def test_wrong_type_is_named(data):
    path = data.draw(st.sampled_from(WRONG_TYPE_PATHS), label="path")
    value = data.draw(_wrong_type(path), label="value")
    assert_error_names(mutate(path, value), field_path(path))


@FUZZ
@given(data=st.data())
def test_out_of_range_is_named(data):
    path, strategy, base = data.draw(st.sampled_from(OUT_OF_RANGE), label="field")
    value = data.draw(strategy, label="value")
    assert_error_names(mutate(path, value, base), field_path(path))


def test_documented_boundaries_are_accepted():
    """The edges of every documented range are inside it: the only refusal that may name the
    field there is a run-plan limit (``limits.*``), never the range itself."""
    for r, base in DOCUMENTED:
        for value in _boundaries(r):
            msg = validate(mutate(r.path, value, base))
            if msg is not None and names(msg, field_path(r.path)):
                assert "more than limits." in msg, (r.dotted, value, msg)


JSONISH = st.recursive(
    st.none() | st.booleans() | st.integers() | st.floats() | st.text(max_size=6),
    lambda inner: st.lists(inner, max_size=3) | st.dictionaries(st.text(max_size=4), inner, max_size=3),
    max_leaves=6,
)


@FUZZ
@given(path=st.sampled_from([p for p, _ in NODES if p]), value=JSONISH)
def test_any_value_anywhere_is_loaded_or_one_line_error(path, value):
    try:
        load_scenario(mutate(path, value))
    except ScenarioError as exc:
        assert "\n" not in str(exc) and str(exc).startswith("<dict>: ")


@FUZZ
@given(text=st.text(max_size=30) | st.from_regex(r"\A[a-z_.0-9]{1,20}=[^\n]{0,15}\Z"))
def test_any_override_is_applied_or_one_line_error(text):
    try:
        load_scenario(BASE, [text])
    except ScenarioError as exc:
        assert "\n" not in str(exc) and "\r" not in str(exc)


# --- property: every in-range scenario loads ----------------------------------------------------

def pos(hi=1e4, lo=1e-3):
    return st.floats(lo, hi)


def _in_range(kind: str, section: str):
    """A dict of random values inside the documented ranges of the scalar floats of ``section``."""
    fields = {}
    for r in documented_ranges(BASE).get(kind, []):
        if r.path[0] != section or len(r.path) != 2 or r.integer:
            continue
        lo = -1e3 if r.lo is None else r.lo
        hi = 1e3 if r.hi is None else r.hi
        fields[r.path[1]] = st.floats(lo, min(hi, lo + 1e3), exclude_min=r.lo_open, exclude_max=r.hi_open
                                      and min(hi, lo + 1e3) == hi)
    return st.fixed_dictionaries({}, optional=fields)


@st.composite
def sims(draw):
    step = draw(st.sampled_from([0.0005, 0.001, 0.002, 0.004, 0.005, 0.01, 0.02, 0.05, 0.1]))
    every = draw(st.integers(1, 50))
    n_steps = every * draw(st.integers(1, 10**6 // every))  # the log divides the duration
    sim = {"dt": step, "log_dt": every * step, "duration": n_steps * step,
           "theta_limit": draw(st.floats(1, 90, exclude_max=True)),
           "state_limit": draw(pos(1e12))}
    if draw(st.booleans()):
        sim["control_rate"] = 1.0 / (draw(st.integers(1, min(100, n_steps))) * step)
    return sim


@st.composite
def envelopes(draw):
    rho0 = draw(st.lists(pos(100), min_size=3, max_size=3))
    frac = draw(st.lists(st.floats(1e-3, 0.99), min_size=3, max_size=3))
    env = draw(_in_range("", "envelope"))
    env.update(kind=draw(st.sampled_from(["none", "rigid", "reactive", "proactive"])),
               rho0=rho0, rho_inf=[r * f for r, f in zip(rho0, frac)],
               widen_start=draw(st.booleans()), baseline=draw(st.sampled_from(["corrected", "printed"])))
    return env


@st.composite
def controllers(draw):
    kind = draw(st.sampled_from(["fxtntsmc", "ftsmc"]))
    return {"kind": kind, **draw(_in_range(kind, "controller"))}


@st.composite
def estimators(draw):
    lo = draw(st.floats(-10, 10))
    wlo = draw(st.floats(-10, 10))
    return {"kind": draw(st.sampled_from(["none", "printed", "omega", "effective"])),
            "neurons": draw(st.integers(1, 50)), "width": draw(pos(100)),
            "centre_range": [lo, lo + draw(pos(10))], "weight_range": [wlo, wlo + draw(st.floats(0, 10))]}


references = st.one_of(
    st.fixed_dictionaries({"kind": st.just("helix")}, optional={
        "radius": pos(1e5), "omega": st.floats(-100, 100), "climb": st.floats(-1000, 1000),
        "center": st.lists(st.floats(-1e3, 1e3), min_size=3, max_size=3), "phase": st.floats(-10, 10)}),
    st.fixed_dictionaries({"kind": st.just("circle"), "radius": pos(1e5), "omega": st.floats(-100, 100),
                           "depth": st.floats(-100, 100)}),
    st.fixed_dictionaries({"kind": st.just("line"),
                           "velocity": st.lists(st.floats(-10, 10), min_size=3, max_size=3)}),
)
disturbances = st.lists(st.one_of(
    st.fixed_dictionaries({"kind": st.just("paper")}, optional={"amplitude": st.floats(0, 10),
                                                                 "phase": st.floats(-10, 10)}),
    st.fixed_dictionaries({"kind": st.just("pulse"), "start": st.floats(0, 100),
                           "duration": pos(100) | st.just("inf"),
                           "force": st.lists(st.floats(-100, 100), min_size=5, max_size=5)}),
), max_size=2)


@st.composite
def windows(draw):
    t0 = draw(st.floats(0, 100))
    return [t0] if draw(st.booleans()) else [t0, draw(st.just(INF) | st.just("inf") | pos(100).map(lambda d: t0 + d))]


scenarios = st.fixed_dictionaries({}, optional={
    "name": st.from_regex(r"\A[A-Za-z0-9_][A-Za-z0-9_.+\-]{0,11}\Z").filter(lambda n: ".." not in n),
    "description": st.text(max_size=20),
    "seed": st.integers(0, 2**32),
    "sim": sims(),
    "vehicle": st.fixed_dictionaries({}, optional={
        "l": st.floats(0, 10, exclude_min=True), "wgml": st.floats(0, 1e3),
        "m": st.lists(pos(), min_size=5, max_size=5), "d": st.lists(st.floats(0, 1e4), min_size=5, max_size=5)}),
    "uncertainty": st.fixed_dictionaries({}, optional={k: st.floats(-0.9, 2.0) for k in "CDMG"}),
    "reference": references,
    "initial": st.fixed_dictionaries({}, optional={
        "eta": st.tuples(*[st.floats(-100, 100)] * 3, st.floats(-0.017, 0.017), st.floats(-10, 10)).map(list),
        "nu": st.lists(st.floats(-10, 10), min_size=5, max_size=5)}),
    "controller": controllers(),
    "envelope": envelopes(),
    "estimator": estimators(),
    "disturbance": disturbances,
    "metrics": st.fixed_dictionaries({"window": windows()}),
    "output": st.fixed_dictionaries({"mat": st.booleans()}),
})


@FUZZ
@given(raw=scenarios)
def test_in_range_scenarios_load_and_round_trip(raw):
    sc = load_scenario(raw)
    assert load_scenario(sc.to_dict()) == sc
    if "sim" in raw:
        assert sc.sim.dt == raw["sim"]["dt"] and sc.sim.duration == raw["sim"]["duration"]
    if "controller" in raw:
        assert sc.controller.kind == raw["controller"]["kind"]


# --- property: `check` refuses exactly what `run` refuses, with the same line -------------------

# what only the run plan or the controller's set-up refuses (load_scenario accepts these)
PLAN_AND_SETUP = [
    (("sim", "dt"), st.floats(1e-300, 1e-7)),
    (("sim", "duration"), st.floats(2e5, 1e300)),
    (("sim", "log_dt"), st.just(0.001)),  # with a long duration (corpus): too many rows
    (("estimator", "neurons"), st.integers(513, 10**9)),
    (("envelope", "widen_start"), st.just(False)),
    (("disturbance",), st.floats(1e-300, 1e-6).map(lambda h: [{"kind": "current", "sample_dt": h}])),
    (("limits", "max_steps"), st.integers(1, 99_999)),
    (("limits", "max_memory_mb"), st.integers(1, 5)),
]


@st.composite
def corpus(draw):
    """A scenario dict from any of the malformation families above, or a valid one."""
    family = draw(st.sampled_from(["range", "type", "key", "any", "plan", "valid"]), label="family")
    if family == "range":
        path, strategy, base = draw(st.sampled_from(OUT_OF_RANGE))
        return mutate(path, draw(strategy), base)
    if family == "type":
        path = draw(st.sampled_from(WRONG_TYPE_PATHS))
        return mutate(path, draw(_wrong_type(path)))
    if family == "key":
        table = draw(st.sampled_from(TABLES))
        return mutate(table + (draw(st.from_regex(r"\Azz_[a-z0-9_]{0,8}\Z")),), draw(st.integers()))
    if family == "any":
        return mutate(draw(st.sampled_from([p for p, _ in NODES if p])), draw(JSONISH))
    if family == "plan":
        path, strategy = draw(st.sampled_from(PLAN_AND_SETUP))
        data = mutate(path, draw(strategy))
        if path == ("sim", "log_dt"):
            data["sim"]["duration"] = 50_000.0
        return data
    return mutate(("sim", "duration"), 0.5)


class _Reached(Exception):
    """Raised instead of simulating: validation passed."""


def _cli(args) -> tuple[object, str]:
    """(exit status or "reached the simulation", stderr) of the CLI with the simulation stubbed out."""
    import contextlib
    import io
    from unittest import mock

    from auvtrack.cli import main

    err = io.StringIO()
    with mock.patch("auvtrack.simulation.pipeline.run_prepared", side_effect=_Reached), \
            contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
        try:
            code = main(args)
        except _Reached:
            code = "reached the simulation"
    return code, err.getvalue()


@settings(max_examples=150, deadline=None)
@given(data=corpus())
def test_check_refuses_exactly_what_run_refuses(data):
    import tempfile

    from auvtrack.scenario.toml_writer import dumps

    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "s.toml"
        try:
            path.write_text(dumps(data), encoding="utf-8")
        except ValueError:  # not representable in TOML (e.g. a None inside an array)
            return
        run_code, run_err = _cli(["run", str(path), "--out", str(Path(tmp) / "out")])
        check_code, check_err = _cli(["check", str(path)])
    event(f"run: {run_code}")
    if run_code == "reached the simulation":
        assert check_code == 0, check_err
    else:
        assert run_code == 2 and check_code == 2, (run_code, check_code, run_err, check_err)
        run_line = [ln for ln in run_err.splitlines() if ln.startswith("auvtrack: error:")]
        check_line = [ln for ln in check_err.splitlines() if ln.startswith("auvtrack: error:")]
        assert len(run_line) == 1 and run_line == check_line, (run_err, check_err)
        assert "Traceback" not in run_err + check_err
