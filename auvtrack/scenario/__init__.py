"""Scenario files: validated model, TOML loading, ``dotted.key=value`` overrides, one-line errors.

>>> from auvtrack.scenario import load_scenario
>>> sc = load_scenario({})            # the paper's Section 4
>>> sc.controller.kind
'fxtntsmc'

See ``docs/scenarios.md`` for every key, its unit, default and allowed range.
"""
from .errors import ScenarioError
from .loader import load_scenario, paper_scenario_path, read_toml
from .overrides import parse_overrides
from .schema import (CONTROLLER_MODELS, EnvelopeSection, EstimatorSection, InitialSection, LimitsSection,
                     MetricsSection, OutputSection, Scenario, SimSection, UncertaintySection,
                     VehicleSection)

__all__ = [
    "ScenarioError", "Scenario", "load_scenario", "paper_scenario_path", "read_toml", "parse_overrides",
    "CONTROLLER_MODELS", "SimSection", "VehicleSection", "UncertaintySection", "InitialSection",
    "EnvelopeSection", "EstimatorSection", "MetricsSection", "OutputSection", "LimitsSection",
]
