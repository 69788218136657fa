"""Crash- and race-safe file output: exclusive temporary files, atomic renames, whole-folder publish.

* Temporary names are unique (``tempfile`` draws them) and created with ``O_CREAT | O_EXCL |
  O_NOFOLLOW``, so a file or symlink already at that name is never opened, let alone its target
  overwritten.
* A file is written under a temporary name in its own folder and renamed over the final name
  (:func:`atomic_file`): a reader sees the old or the new file, never a partial one.
* A folder is written as a whole under a unique temporary name and renamed into place
  (:func:`publish_folder`): the final folder is always absent or one writer's complete output,
  even with concurrent writers.  ``rename(2)`` of a directory onto a non-empty directory fails
  atomically, which is what makes the swap safe; :func:`publish_new_folder` uses the same
  failure to give concurrent writers each a folder of their own (``runs/x``, ``runs/x-2``...).
"""
from __future__ import annotations

import contextlib
import errno
import os
import shutil
import tempfile
import uuid
from pathlib import Path
from typing import BinaryIO, Callable, Iterator

__all__ = ["open_exclusive", "atomic_file", "atomic_write", "make_temp_folder", "publish_folder",
           "publish_new_folder", "FolderError"]

_UMASK = os.umask(0o022)
os.umask(_UMASK)
_EXCLUSIVE = os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_NOFOLLOW", 0) | getattr(os, "O_CLOEXEC", 0)


class FolderError(OSError):
    """An output folder that cannot be written or replaced; ``str(err)`` is one line."""


def open_exclusive(path: str | os.PathLike) -> BinaryIO:
    """Create ``path`` for writing; fail if anything (a file, a symlink) is already there.

    Parameters
    ----------
    path : str or path-like
        The new file.

    Returns
    -------
    file object
        Opened in binary write mode.
    """
    fd = os.open(path, _EXCLUSIVE, 0o666)
    return os.fdopen(fd, "wb")


@contextlib.contextmanager
def atomic_file(path: str | os.PathLike) -> Iterator[BinaryIO]:
    """Write ``path`` atomically: yield a binary file under a unique temporary name, then rename.

    On an exception the temporary file is removed and ``path`` is untouched.

    Parameters
    ----------
    path : str or path-like
        Final file name (its folder must exist).

    Yields
    ------
    file object
        Binary, write mode.
    """
    path = Path(path)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name[:64]}.", suffix=".tmp")
    try:
        with os.fdopen(fd, "wb") as fh:
            yield fh
        os.chmod(tmp, 0o666 & ~_UMASK)  # mkstemp creates 0600
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise


def atomic_write(path: str | os.PathLike, data: str | bytes) -> None:
    """Write ``data`` (text as UTF-8 with ``\\n`` newlines) to ``path`` atomically.

    Parameters
    ----------
    path : str or path-like
        Final file name.
    data : str or bytes
        Content.
    """
    with atomic_file(path) as fh:
        fh.write(data.encode("utf-8") if isinstance(data, str) else data)


def make_temp_folder(final: Path) -> Path:
    """Create a new, empty, uniquely named folder next to ``final`` (same file system).

    Parameters
    ----------
    final : Path
        The folder that will eventually be published; its parent must exist.

    Returns
    -------
    Path
        ``<parent>/.<name>.tmp-<random>`` (name cut to 64 characters), with the permissions a
        plain ``mkdir`` would give.
    """
    tmp = Path(tempfile.mkdtemp(dir=final.parent, prefix=f".{final.name[:64]}.tmp-"))
    os.chmod(tmp, 0o777 & ~_UMASK)
    return tmp


def publish_new_folder(tmp: Path, candidates: Iterator[Path], attempts: int = 100_000) -> Path:
    """Rename the complete folder ``tmp`` to the first of ``candidates`` that is free (absent or empty).

    Concurrent writers each get their own folder: a name taken in the meantime is skipped.

    Parameters
    ----------
    tmp : Path
        The finished folder (from :func:`make_temp_folder`).
    candidates : iterator of Path
        Names to try, in order (same file system as ``tmp``).
    attempts : int, optional
        Bound on the names tried.

    Returns
    -------
    Path
        The name ``tmp`` now has.

    Raises
    ------
    FolderError
        No free name among the first ``attempts`` (``tmp`` is kept, and named in the message).
    """
    for _, final in zip(range(attempts), candidates):
        try:
            os.rename(tmp, final)
            return final
        except OSError as exc:
            if exc.errno not in (errno.ENOTEMPTY, errno.EEXIST, errno.ENOTDIR, errno.EISDIR):
                raise
    raise FolderError(f"no free folder name after {attempts} attempts; the complete output is kept in {tmp}")


def publish_folder(tmp: Path, final: Path, replaceable: Callable[[Path], str | None],
                   attempts: int = 1000) -> None:
    """Rename the complete folder ``tmp`` to ``final``, replacing an existing ``final`` atomically.

    Parameters
    ----------
    tmp : Path
        The finished folder (from :func:`make_temp_folder`).
    final : Path
        Its final name.
    replaceable : callable
        ``replaceable(final)`` returns None when the existing ``final`` may be replaced, else the
        reason (one line) why not.
    attempts : int, optional
        Bound on the retries when concurrent writers keep replacing ``final``.

    Raises
    ------
    FolderError
        ``final`` exists and may not be replaced (``tmp`` is then kept, and named in the message).
    """
    for _ in range(attempts):
        try:
            os.rename(tmp, final)  # atomic; refuses a non-empty folder, a file or a symlink
            return
        except OSError as exc:
            if exc.errno not in (errno.ENOTEMPTY, errno.EEXIST, errno.ENOTDIR, errno.EISDIR):
                raise
        before = _identity(final)
        if before is None:
            continue  # another writer moved it aside meanwhile: try the rename again
        reason = replaceable(final)
        if reason is not None:
            if _identity(final) != before:
                continue  # moved or replaced by another writer while it was being checked: look again
            raise FolderError(f"{reason}; the complete output is kept in {tmp}")
        old = final.with_name(f".{final.name[:64]}.old-{uuid.uuid4().hex[:12]}")
        try:
            os.rename(final, old)  # move the previous complete folder aside, atomically
        except FileNotFoundError:
            continue  # another writer moved it first
        if replaceable(old) is not None:  # it changed between the check and the move: put it back
            with contextlib.suppress(OSError):
                os.rename(old, final)
            raise FolderError(f"{final}: changed while the run was being published; the complete output "
                              f"is kept in {tmp}")
        shutil.rmtree(old, ignore_errors=True)
    raise FolderError(f"{final}: could not be replaced after {attempts} attempts (other writers); "
                      f"the complete output is kept in {tmp}")


def _identity(path: Path) -> tuple[int, int] | None:
    """(device, inode) of ``path`` itself (a link is not followed), or None when nothing is there."""
    try:
        st = os.lstat(path)
    except FileNotFoundError:
        return None
    return st.st_dev, st.st_ino
