"""Seeding contract: every random stream is derived from the scenario seed and a purpose name.

``rng(seed, "current/0")`` and ``rng(seed, "rbf")`` are independent streams, so adding a new
random component never changes the numbers drawn by another one (Gymnasium-style seeding).
"""
from __future__ import annotations

import zlib

import numpy as np


def rng(seed: int, purpose: str) -> np.random.Generator:
    """Return a NumPy generator for ``purpose`` derived deterministically from ``seed``."""
    return np.random.default_rng(np.random.SeedSequence([int(seed), zlib.crc32(purpose.encode())]))
