"""Property tests of scenario validation: every malformation is a one-line ScenarioError naming
the mutated field, every in-range scenario loads and round-trips."""
from __future__ import annotations

import copy
import math
import types
import typing
from pathlib import Path

import annotated_types as at
from hypothesis import given, settings
from hypothesis import strategies as st
from pydantic.fields import FieldInfo

from auvtrack.control.params import FTSMCParams, FXTNTSMCParams
from auvtrack.scenario import ScenarioError, load_scenario
from auvtrack.scenario import schema

PAPER = Path(__file__).resolve().parents[1] / "scenarios" / "paper.toml"
BASE = load_scenario(PAPER).to_dict()  # valid, every leaf spelled out
FUZZ = settings(max_examples=200, deadline=None)
SECTIONS = {"sim": schema.SimSection, "vehicle": schema.VehicleSection,
            "uncertainty": schema.UncertaintySection, "initial": schema.InitialSection,
            "envelope": schema.EnvelopeSection, "estimator": schema.EstimatorSection,
            "controller": FXTNTSMCParams}
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


def mutate(path, value) -> dict:
    data = copy.deepcopy(BASE)
    node = data
    for seg in path[:-1]:
        node = node[seg]
    node[path[-1]] = value
    return data


def assert_error_names(data, path: str) -> None:
    try:
        load_scenario(data)
    except ScenarioError as exc:
        msg = str(exc)
    else:
        raise AssertionError(f"no error for a malformed {path}")
    assert "\n" not in msg and "\r" not in msg, msg
    prefix = "<dict>: "
    assert msg.startswith(prefix), msg
    body = msg[len(prefix):]
    assert body.startswith(path) and body[len(path)] in ".:", (path, msg)


# --- forbidden ranges, derived from the models' constraints plus the cross-field rules ----------

def _collect(annotation, metadata=()):
    meta = list(metadata)
    while True:
        origin = typing.get_origin(annotation)
        if origin is typing.Annotated:
            base, *extra = typing.get_args(annotation)
            for m in extra:
                meta.extend(m.metadata if isinstance(m, FieldInfo) else [m])
            annotation = base
        elif origin in (typing.Union, types.UnionType):
            annotation = [a for a in typing.get_args(annotation) if a is not type(None)][0]
        else:
            return annotation, meta


def _bounds(meta) -> dict:
    out = {}
    for m in meta:
        for name, cls in (("gt", at.Gt), ("ge", at.Ge), ("lt", at.Lt), ("le", at.Le)):
            if isinstance(m, cls):
                out[name] = getattr(m, name)
    return out


def below(x: float) -> float:
    """Largest float < x (explicit: hypothesis may turn ``x < 0`` filters into -0.0)."""
    return math.nextafter(float(x), -INF)


def above(x: float) -> float:
    """Smallest float > x."""
    return math.nextafter(float(x), INF)


def _outside(b: dict, is_int: bool):
    parts = []
    if is_int:
        if "ge" in b:
            parts.append(st.integers(max_value=b["ge"] - 1))
        if "le" in b:
            parts.append(st.integers(min_value=b["le"] + 1))
        return st.one_of(parts)
    if "gt" in b:
        parts.append(st.floats(max_value=b["gt"], allow_nan=False))
    if "ge" in b:
        parts.append(st.floats(max_value=below(b["ge"]), allow_nan=False))
    if "lt" in b:
        parts.append(st.floats(min_value=b["lt"], allow_nan=False))
    if "le" in b:
        parts.append(st.floats(min_value=above(b["le"]), allow_nan=False))
    return st.one_of(parts)


def _constrained():
    """(path, strategy of forbidden values) for every range-constrained number of the models."""
    out = []
    for section, model in SECTIONS.items():
        for name, f in model.model_fields.items():
            ann, meta = _collect(f.annotation, f.metadata)
            if ann in (float, int) and _bounds(meta):
                out.append(((section, name), _outside(_bounds(meta), ann is int)))
            elif typing.get_origin(ann) is tuple:
                for i, item in enumerate(typing.get_args(ann)):
                    iann, imeta = _collect(item)
                    if _bounds(imeta):
                        out.append(((section, name, i), _outside(_bounds(imeta), iann is int)))
    return out


def _not_multiple(step: float, kmin: int):
    return st.builds(lambda k, f: (k + f) * step, st.integers(kmin, 10_000), st.floats(0.01, 0.99))


dt = BASE["sim"]["dt"]
CROSS = [
    (("sim", "log_dt"), st.floats(0, dt, exclude_min=True, exclude_max=True)),
    (("sim", "log_dt"), _not_multiple(dt, 1)),
    (("sim", "duration"), _not_multiple(dt, 1)),
    (("sim", "control_rate"), _not_multiple(dt, 1).map(lambda p: 1.0 / p)),
    (("initial", "eta", 3), st.floats(math.pi / 2, allow_nan=False) | st.floats(max_value=-math.pi / 2)),
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


def _get(path):
    node = BASE
    for seg in path:
        node = node[seg]
    return node


# every number must be finite (metrics.window[1] alone may be inf)
NON_FINITE = [(p, st.sampled_from([INF, -INF, math.nan])) for p in SCALARS
              if isinstance(_get(p), float) and p != ("metrics", "window", 1)]
OUT_OF_RANGE = _constrained() + CROSS + NON_FINITE


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
    path, strategy = data.draw(st.sampled_from(OUT_OF_RANGE), label="field")
    value = data.draw(strategy, label="value")
    assert_error_names(mutate(path, value), field_path(path))


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


def _in_range(model):
    """A dict of random in-range values for the range-constrained float fields of ``model``."""
    fields = {}
    for name, f in model.model_fields.items():
        ann, meta = _collect(f.annotation, f.metadata)
        if ann is not float:
            continue
        b = _bounds(meta)
        lo = b.get("gt", b.get("ge", -1e3))
        hi = b.get("lt", b.get("le", 1e3))
        fields[name] = st.floats(lo, min(hi, lo + 1e3), exclude_min="gt" in b, exclude_max="lt" in b)
    return st.fixed_dictionaries({}, optional=fields)


@st.composite
def sims(draw):
    step = draw(st.sampled_from([0.0005, 0.001, 0.002, 0.004, 0.005, 0.01, 0.02, 0.05, 0.1]))
    sim = {"dt": step, "log_dt": draw(st.integers(1, 50)) * step,
           "duration": draw(st.integers(1, 10**6)) * step,
           "theta_limit": draw(st.floats(0, 90, exclude_min=True, exclude_max=True)),
           "state_limit": draw(pos(1e12))}
    if draw(st.booleans()):
        sim["control_rate"] = 1.0 / (draw(st.integers(1, 100)) * step)
    return sim


@st.composite
def envelopes(draw):
    rho0 = draw(st.lists(pos(100), min_size=3, max_size=3))
    frac = draw(st.lists(st.floats(1e-3, 0.99), min_size=3, max_size=3))
    env = draw(_in_range(schema.EnvelopeSection))
    env.update(kind=draw(st.sampled_from(["none", "rigid", "reactive", "proactive"])),
               rho0=rho0, rho_inf=[r * f for r, f in zip(rho0, frac)],
               widen_start=draw(st.booleans()), baseline=draw(st.sampled_from(["corrected", "printed"])))
    return env


@st.composite
def controllers(draw):
    kind = draw(st.sampled_from(["fxtntsmc", "ftsmc"]))
    model = FXTNTSMCParams if kind == "fxtntsmc" else FTSMCParams
    return {"kind": kind, **draw(_in_range(model))}


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
    "name": st.from_regex(r"\A[A-Za-z0-9_\-]{1,12}\Z"),
    "description": st.text(max_size=20),
    "seed": st.integers(0, 2**32),
    "sim": sims(),
    "vehicle": st.fixed_dictionaries({}, optional={
        "l": st.floats(0, 10, exclude_min=True), "wgml": st.floats(0, 1e3),
        "m": st.lists(pos(), min_size=5, max_size=5), "d": st.lists(st.floats(0, 1e4), min_size=5, max_size=5)}),
    "uncertainty": st.fixed_dictionaries({}, optional={k: st.floats(-0.9, 2.0) for k in "CDMG"}),
    "reference": references,
    "initial": st.fixed_dictionaries({}, optional={
        "eta": st.tuples(*[st.floats(-100, 100)] * 3, st.floats(-1.57, 1.57), st.floats(-10, 10)).map(list),
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
