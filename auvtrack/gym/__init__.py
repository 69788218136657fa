"""Gymnasium environments of the benchmark suites: ``gymnasium.make("auvtrack/Track-v0", suite=..., task=..., tier=...)``.

Importing this package registers them (docs/gym.md).
"""
import gymnasium

ENV_ID = "auvtrack/Track-v0"
if ENV_ID not in gymnasium.registry:
    gymnasium.register(ENV_ID, entry_point="auvtrack.gym.env:TrackEnv")

__all__ = ["ENV_ID", "VECTOR_ID"]

VECTOR_ID = "auvtrack/Track-v0-vector"
"""The vector form (:class:`auvtrack.gym.vector.TrackVectorEnv`): ``auvtrack.gym.vector.TrackVectorEnv(n, ...)``."""
