"""Renamed controller channels and their old names, readable for one more release.

Until 0.1 the FXTNTSMC logged its sliding variable as ``S_x`` and its transformed error (eq. 17)
as ``z_x``, right beside the position ``z``, and the FTSMC logged its sliding variable as ``s_x``.
Both controllers now log ``sliding_x, sliding_y, sliding_z`` and the FXTNTSMC logs
``zeta_x, zeta_y, zeta_z``.  The old names stay readable for one release:
``res["S_x"]`` returns ``res["sliding_x"]`` with a :class:`FutureWarning`,
:meth:`~auvtrack.simulation.result.Result.to_pandas` adds the old columns unless
``legacy_names=False``, and :meth:`~auvtrack.simulation.result.Result.load` reads run folders
written with the old names.  The old names will be removed in the next release.
"""
from __future__ import annotations

import warnings
from typing import Iterable, Mapping

AXES = ("x", "y", "z")

LEGACY_NAMES: dict[str, dict[str, str]] = {
    "fxtntsmc": {**{f"S_{a}": f"sliding_{a}" for a in AXES}, **{f"z_{a}": f"zeta_{a}" for a in AXES}},
    "ftsmc": {f"s_{a}": f"sliding_{a}" for a in AXES},
}
"""``{controller kind: {old channel name: new channel name}}``."""

ALL_LEGACY: dict[str, str] = {old: new for table in LEGACY_NAMES.values() for old, new in table.items()}
"""Every old name, whatever the controller."""

DEPRECATION = ("channel {old!r} is deprecated and will be removed in the next release; "
               "use {new!r} (docs/metrics.md)")


def legacy_table(kind: str | None) -> dict[str, str]:
    """Old -> new names of one controller kind (every old name when the kind is unknown).

    Parameters
    ----------
    kind : str or None
        Controller kind, e.g. ``"fxtntsmc"``.

    Returns
    -------
    dict of str to str
        ``{old name: new name}``.
    """
    return dict(LEGACY_NAMES.get(kind or "", ALL_LEGACY))


def current_name(name: str, names: Iterable[str], kind: str | None = None, *, warn: bool = True) -> str | None:
    """The channel an old ``name`` now stands for, if it is an old name and that channel exists.

    Parameters
    ----------
    name : str
        Requested channel name.
    names : iterable of str
        Channels that exist.
    kind : str, optional
        Controller kind, restricting the old names to that controller's.
    warn : bool, optional
        Emit a :class:`FutureWarning` naming the new channel.

    Returns
    -------
    str or None
        The new name, or ``None`` if ``name`` is not an old name of an existing channel.
    """
    new = legacy_table(kind).get(name)
    if new is None or new not in set(names):
        return None
    if warn:
        warnings.warn(DEPRECATION.format(old=name, new=new), FutureWarning, stacklevel=3)
    return new


def upgrade_names(names: Iterable[str], kind: str | None = None) -> list[str]:
    """Rename old channel names of a run folder written before the rename.

    Parameters
    ----------
    names : iterable of str
        Column names as written (e.g. the ``trajectory.csv`` header).
    kind : str, optional
        Controller kind of the run.

    Returns
    -------
    list of str
        The names with every old name replaced by its new one (names already new are kept).
    """
    names = list(names)
    table = legacy_table(kind)
    present = set(names)
    return [table[n] if n in table and table[n] not in present else n for n in names]


def legacy_columns(names: Iterable[str], kind: str | None) -> Mapping[str, str]:
    """``{old name: new name}`` for the channels of ``names`` that had an old name under ``kind``.

    Parameters
    ----------
    names : iterable of str
        Channels that exist.
    kind : str or None
        Controller kind; with an unknown kind no old column is invented.

    Returns
    -------
    dict of str to str
        Empty unless ``kind`` is a controller whose channels were renamed.
    """
    present = set(names)
    return {old: new for old, new in LEGACY_NAMES.get(kind or "", {}).items() if new in present and old not in present}


__all__ = ["LEGACY_NAMES", "ALL_LEGACY", "legacy_table", "current_name", "upgrade_names", "legacy_columns"]
