"""Registry of ``auvtrack study NAME`` studies.

A study is one module of :mod:`auvtrack.studies` that defines a module-level
``STUDY = StudySpec(...)``.  :func:`all_studies` discovers every such module, so adding a study
means adding one file; nothing else is edited.  Importing a study module must not compile or
run anything.
"""
from __future__ import annotations

import importlib
import pkgutil
from dataclasses import dataclass
from pathlib import Path
from typing import Callable, Iterable, Protocol


class StudyRunner(Protocol):
    """Signature of a study's entry point."""

    def __call__(self, out: Path, *, quick: bool = False, progress: bool = False) -> Path:
        """Run the study, write its report and data under ``out``; return the report's path."""


@dataclass(frozen=True)
class StudySpec:
    """Registration record of one study.

    Attributes
    ----------
    name : str
        Command-line name (``auvtrack study NAME``).
    run : callable
        ``run(out, *, quick=False, progress=False) -> Path`` (see :class:`StudyRunner`).
    summary : str
        One line shown by ``auvtrack study --help``.
    options : tuple of str
        Keyword options of ``run`` beyond ``quick`` and ``progress`` that the command line may
        pass (e.g. ``("pulse", "pulse_start")`` for ``--pulse``, ``--pulse-start``).
    """

    name: str
    run: Callable[..., Path]
    summary: str = ""
    options: tuple[str, ...] = ()


def run_study(spec: StudySpec, out: Path, *, quick: bool = False, progress: bool = False, **options) -> Path:
    """Run a registered study; a ``quick`` run's report opens with a banner and its results.json says ``"quick": true``.

    Parameters
    ----------
    spec : StudySpec
        The study.
    out : pathlib.Path
        Output folder.
    quick, progress : bool, optional
        Passed to the study's ``run``.
    **options
        The study's own options (:attr:`StudySpec.options`).

    Returns
    -------
    pathlib.Path
        The report's path.
    """
    from ..report import quick_outputs

    with quick_outputs(quick):
        return spec.run(out, quick=quick, progress=progress, **options)


def kinds_in(overrides: Iterable[str]) -> list[str]:
    """The controller kinds that ``controller.kind=...`` overrides name (for :func:`~auvtrack.simulation.compiling.compile_first`).

    Parameters
    ----------
    overrides : iterable of str
        ``--set``-style overrides.

    Returns
    -------
    list of str
        Every kind named, in order, without repeats.
    """
    kinds = [o.split("=", 1)[1].strip() for o in overrides if o.replace(" ", "").startswith("controller.kind=")]
    return list(dict.fromkeys(kinds))


def all_studies() -> dict[str, StudySpec]:
    """Discover every study module of :mod:`auvtrack.studies`.

    Returns
    -------
    dict of str to StudySpec
        ``{name: spec}`` in alphabetical order of the modules.

    Raises
    ------
    ValueError
        If two modules register the same study name.
    """
    from .. import studies as pkg

    found: dict[str, StudySpec] = {}
    for info in sorted(pkgutil.iter_modules(pkg.__path__), key=lambda i: i.name):
        mod = importlib.import_module(f"{pkg.__name__}.{info.name}")
        spec = getattr(mod, "STUDY", None)
        if isinstance(spec, StudySpec):
            if spec.name in found:
                raise ValueError(f"study {spec.name!r} is registered twice")
            found[spec.name] = spec
    return found


def get_study(name: str) -> StudySpec:
    """Return a registered study.

    Parameters
    ----------
    name : str
        Study name, e.g. ``"ablation"``.

    Returns
    -------
    StudySpec
        Its registration record.

    Raises
    ------
    KeyError
        If there is no such study (the message names the choices).
    """
    studies = all_studies()
    try:
        return studies[name]
    except KeyError:
        raise KeyError(f"unknown study {name!r}; choose one of {sorted(studies)}") from None
