"""Shared test settings: compiled kernels make the first example slow, so no hypothesis deadline."""
import os

import matplotlib
from hypothesis import settings

matplotlib.use("Agg")
settings.register_profile("auvtrack", deadline=None, print_blob=True)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "auvtrack"))
