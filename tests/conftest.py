"""Shared test settings: compiled kernels make the first example slow, so no hypothesis deadline."""
import os

import matplotlib
from hypothesis import settings

matplotlib.use("Agg")
settings.register_profile("auvtrack", deadline=None, print_blob=True)
# CI replays a fixed, reproducible set of examples (a red CI must be re-runnable as it was)
settings.register_profile("ci", parent=settings.get_profile("auvtrack"), derandomize=True)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "ci" if os.environ.get("CI") else "auvtrack"))
