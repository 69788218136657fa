"""Deprecated location of :mod:`auvtrack.runner.batch` (moved in 0.2; this alias goes in 0.3)."""
import warnings

from ..runner.batch import *  # noqa: F401,F403
from ..runner.batch import __all__  # noqa: F401

warnings.warn("auvtrack.simulation.batch moved to auvtrack.runner.batch", DeprecationWarning, stacklevel=2)
