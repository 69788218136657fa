"""Shared test settings: compiled kernels make the first example slow, so no hypothesis deadline."""
import os

import matplotlib
from hypothesis import settings

matplotlib.use("Agg")
settings.register_profile("auvtrack", deadline=None, print_blob=True)
# CI replays a fixed, reproducible set of examples (a red CI must be re-runnable as it was)
settings.register_profile("ci", parent=settings.get_profile("auvtrack"), derandomize=True)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "ci" if os.environ.get("CI") else "auvtrack"))


def pytest_collection_finish(session):
    """Before a large run (the whole suite), compile every built-in kernel in parallel child
    processes, one per core, instead of one after another inside the tests that first need them.
    A run of a few tests skips this; ``AUVTRACK_TEST_WARMUP=0`` turns it off."""
    if len(session.items) < 200 or os.environ.get("AUVTRACK_TEST_WARMUP", "1") == "0":
        return
    from auvtrack.simulation.compiling import warmup

    warmup(progress=False)
