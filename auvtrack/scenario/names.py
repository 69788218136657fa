"""Names that become folder names (``runs/<name>``, ``sweeps/<name>``): one rule for all.

A name is 1 to 100 characters from letters, digits, ``_``, ``-``, ``.`` and ``+``, starting with a
letter, digit or ``_``: no path separator, no ``..``, no NUL or other control character, no leading
dot (hidden folder) or dash (read as an option), short enough for every file system.
"""
from __future__ import annotations

import re

__all__ = ["NAME_RULE", "check_name"]

NAME_RULE = "1 to 100 characters from A-Z a-z 0-9 _ - . +, starting with a letter, digit or _"
_NAME = re.compile(r"[A-Za-z0-9_][A-Za-z0-9_.+\-]{0,99}")


def check_name(value: str) -> str:
    """Return ``value`` if it is a valid run or sweep name, else raise ``ValueError``.

    Parameters
    ----------
    value : str
        The candidate name.

    Returns
    -------
    str
        ``value`` unchanged.

    Raises
    ------
    ValueError
        ``"must be <rule> (got <value>)"``.
    """
    if not isinstance(value, str) or not _NAME.fullmatch(value) or ".." in value:
        shown = repr(value) if not isinstance(value, str) or len(value) <= 60 else repr(value[:57] + "...")
        raise ValueError(f"must be {NAME_RULE}, without '..' (got {shown})")
    return value
