"""Plant registry: the truth models the engine can integrate.

A plant is one module that defines the compiled functions of the plant contract
(``docs/architecture.md``, "The plant contract"): ``NX``, ``N_CMD``, ``N_LOG``, ``pose``, ``accel5``,
``allocate``, ``rhs``, ``applied``, ``attitude_cause`` and ``log_extra``, and a Python ``setup``
that packs its parameters and initial state.  Registering a plant is one line in
:mod:`auvtrack.plant` (``register(PlantSpec.from_module(module))``); the engine's kernel for a
(controller, plant) pair is generated on demand (:mod:`auvtrack.engine.kernels`).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from types import ModuleType
from typing import Any, Callable

import numpy as np

CONTRACT = ("NX", "N_CMD", "N_LOG", "pose", "accel5", "allocate", "rhs", "applied", "attitude_cause",
            "log_extra", "setup")


@dataclass(frozen=True)
class CompiledPlant:
    """What the engine needs of one plant for one run.

    Attributes
    ----------
    pp : numpy.ndarray
        Packed float64 parameters of the true plant (layout defined by the plant module).
    x0 : numpy.ndarray
        Initial plant state, length ``NX`` of the module.
    log_names : tuple of str
        Names of the plant's extra logged channels (``N_LOG`` of them).
    notes : tuple of str
        Messages to show the user.
    resolved : dict
        JSON record of the plant actually simulated (numbers and their sources) for ``run.json``.
    module : str
        Importable name of the module whose compiled functions run this plant; empty = the
        registered spec's module.  A plant with presets of different equations (``"6dof"``)
        names the preset's module here, so each gets its own kernel.
    """

    pp: np.ndarray
    x0: np.ndarray
    log_names: tuple[str, ...] = ()
    notes: tuple[str, ...] = ()
    resolved: dict[str, Any] = field(default_factory=dict)
    module: str = ""


@dataclass(frozen=True)
class PlantSpec:
    """Registration record of one plant model.

    Attributes
    ----------
    name : str
        Value of the scenario key ``plant.model``.
    module : str
        Importable name of the module with the compiled contract functions.
    setup : callable
        ``setup(scenario) -> CompiledPlant``.
    summary : str
        One line for listings.
    presets : dict of str to str
        For a plant whose presets have different equations: preset name -> the module that
        runs it (the module's ``MODULES``); empty when ``module`` runs every preset.
    """

    name: str
    module: str
    setup: Callable[..., CompiledPlant]
    summary: str = ""
    presets: dict[str, str] = field(default_factory=dict)

    @property
    def kernel_modules(self) -> dict[str, str]:
        """Label -> module of every kernel this plant can need (one per preset module)."""
        if not self.presets:
            return {self.name: self.module}
        return {f"{self.name}/{preset}": mod for preset, mod in self.presets.items()}

    @classmethod
    def from_module(cls, module: ModuleType) -> "PlantSpec":
        """Build the record from a plant module (its ``NAME``, ``setup`` and docstring).

        Parameters
        ----------
        module : module
            A module defining every name of :data:`CONTRACT` and ``NAME``.

        Returns
        -------
        PlantSpec
            The record.

        Raises
        ------
        TypeError
            If the module lacks a name of the contract.
        """
        missing = [n for n in ("NAME",) + CONTRACT if not hasattr(module, n)]
        if missing:
            raise TypeError(f"plant module {module.__name__} lacks {', '.join(missing)}")
        summary = (module.__doc__ or "").strip().splitlines()[0] if module.__doc__ else ""
        return cls(module.NAME, module.__name__, module.setup, summary, dict(getattr(module, "MODULES", {})))


PLANTS: dict[str, PlantSpec] = {}


def register(spec: PlantSpec) -> PlantSpec:
    """Add ``spec`` to :data:`PLANTS`.

    Parameters
    ----------
    spec : PlantSpec
        The record; its name must be unused.

    Returns
    -------
    PlantSpec
        ``spec`` itself.

    Raises
    ------
    ValueError
        If the name is already registered.
    """
    if spec.name in PLANTS:
        raise ValueError(f"plant {spec.name!r} is already registered")
    PLANTS[spec.name] = spec
    return spec


def get(name: str) -> PlantSpec:
    """Return a registered plant.

    Parameters
    ----------
    name : str
        A ``plant.model`` value, e.g. ``"5dof"``.

    Returns
    -------
    PlantSpec
        Its registration record.

    Raises
    ------
    KeyError
        If ``name`` is not registered (the message names the choices).
    """
    try:
        return PLANTS[name]
    except KeyError:
        raise KeyError(f"unknown plant {name!r}; choose one of {sorted(PLANTS)}") from None
