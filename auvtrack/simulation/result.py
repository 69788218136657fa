"""The outcome of one simulation: logged channels, metrics, status, and the run-folder format.

A run folder holds ``trajectory.csv`` (bit-exact text), ``run.json`` (scenario, status, failure,
metrics, meta), ``scenario.toml`` (the fully resolved scenario: ``auvtrack run`` on it reproduces
``trajectory.csv`` byte for byte) and optionally ``trajectory.mat``; ``docs/metrics.md`` is the
contract.  A folder is written whole under a unique temporary name and renamed into place
(:mod:`auvtrack._atomic`), so it is always one run's complete output, even when several runs
write to the same folder at once.
"""
from __future__ import annotations

import hashlib
import itertools
import json
import math
import os
import re
import shutil
import stat
from pathlib import Path
from typing import Any, BinaryIO, Callable, Iterator, Mapping

import numpy as np

from .._atomic import FolderError, make_temp_folder, open_exclusive, publish_folder, publish_new_folder
from ..channels import BASE_CHANNELS

STATUSES = ("ok", "failed", "interrupted")
FAILURE_KEYS = ("time", "cause", "detail", "state")
CSV_NAME, JSON_NAME, MAT_NAME, TOML_NAME = "trajectory.csv", "run.json", "trajectory.mat", "scenario.toml"
RUN_FILES = (CSV_NAME, JSON_NAME, TOML_NAME, MAT_NAME)
"""The only entries of a run folder; an existing folder holding anything else is never replaced."""
CSV_BLOCK_ROWS = 2000  # rows formatted at a time: the CSV writer's memory does not grow with the run
MAT_RESERVED = ("channel_names", "scenario_json", "failure_json", "status", "metrics", "version")
_NAME_RE = re.compile(r"^[A-Za-z][A-Za-z0-9_]{0,62}$")  # also a valid MATLAB variable name


# ---------------------------------------------------------------- JSON helpers
def _ptr_escape(key: str) -> str:
    return key.replace("~", "~0").replace("/", "~1")


def _ptr_unescape(token: str) -> str:
    return token.replace("~1", "/").replace("~0", "~")


def to_jsonable(obj: Any, nonfinite: dict[str, str] | None = None, path: str = "") -> Any:
    """Convert ``obj`` to plain JSON types; non-finite floats become ``None``.

    Parameters
    ----------
    obj : object
        Nested dicts, lists, tuples, NumPy arrays and scalars, floats, paths...
    nonfinite : dict, optional
        If given, receives ``{json_pointer: "inf" | "-inf" | "nan"}`` for every non-finite float
        replaced by ``None`` (RFC 6901 pointers, e.g. ``/metrics/settle_1mm_x``).
    path : str, optional
        JSON pointer of ``obj`` itself (used in the recursion).

    Returns
    -------
    object
        Something :func:`json.dumps` accepts with ``allow_nan=False``.
    """
    if isinstance(obj, np.ndarray):
        obj = obj.tolist()
    elif isinstance(obj, np.generic):
        obj = obj.item()
    if obj is None or isinstance(obj, (bool, str)):
        return obj
    if isinstance(obj, int):
        return int(obj)
    if isinstance(obj, float):
        if math.isfinite(obj):
            return float(obj)
        if nonfinite is not None:
            nonfinite[path] = "nan" if math.isnan(obj) else ("inf" if obj > 0 else "-inf")
        return None
    if isinstance(obj, Mapping):
        return {str(k): to_jsonable(v, nonfinite, f"{path}/{_ptr_escape(str(k))}") for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [to_jsonable(v, nonfinite, f"{path}/{i}") for i, v in enumerate(obj)]
    if isinstance(obj, os.PathLike):
        return os.fspath(obj)
    return str(obj)


def restore_nonfinite(doc: Any, nonfinite: Mapping[str, str]) -> Any:
    """Put the non-finite floats recorded by :func:`to_jsonable` back into ``doc`` (in place).

    Parameters
    ----------
    doc : dict or list
        Parsed JSON document.
    nonfinite : mapping of str to str
        ``{json_pointer: "inf" | "-inf" | "nan"}``; pointers that no longer resolve are ignored.

    Returns
    -------
    dict or list
        ``doc`` itself.
    """
    for ptr, val in nonfinite.items():
        tokens = [_ptr_unescape(tok) for tok in ptr.split("/")[1:]]
        if not tokens:
            continue
        node = doc
        try:
            for tok in tokens[:-1]:
                node = node[int(tok)] if isinstance(node, list) else node[tok]
            last = tokens[-1]
            if isinstance(node, list):
                node[int(last)] = float(val)
            elif last in node:
                node[last] = float(val)
        except (KeyError, IndexError, ValueError, TypeError):
            continue
    return doc


def _name_max(folder: Path) -> int:
    try:
        return os.pathconf(folder if folder.is_dir() else ".", "PC_NAME_MAX")
    except (OSError, ValueError):
        return 255


def run_folder_problem(folder: str | os.PathLike) -> str | None:
    """Why ``folder`` cannot become a run folder, or None when it can (absent, empty or a run folder).

    Parameters
    ----------
    folder : str or path-like
        The intended run folder.

    Returns
    -------
    str or None
        One line naming the folder and the problem: a NUL character or an over-long name, a
        file or a symbolic link at that path, or a folder holding entries other than
        :data:`RUN_FILES` (which would be lost when the run replaces it).
    """
    text = os.fspath(folder)
    if "\x00" in text:
        return f"{text!r}: a path cannot contain a NUL character"
    if not text.strip():
        return "the run folder path is empty"
    path = Path(text)
    if path.name in ("", ".", ".."):
        return f"{text}: must name a folder of its own (not '.', '..' or '/')"
    limit = _name_max(path.parent)
    long = [p for p in path.parts if len(p.encode("utf-8", "surrogateescape")) > limit]
    if long:
        return f"{text}: the name {long[0][:40]!r}... is longer than {limit} bytes"
    try:  # one look at the path itself: concurrent writers rename run folders in and out of it
        mode = os.lstat(path).st_mode
    except (FileNotFoundError, NotADirectoryError):  # absent (a parent that is a file: reported on creation)
        return None
    except OSError as exc:
        return f"{text}: cannot be read ({exc.strerror or exc})"
    if stat.S_ISLNK(mode):
        return f"{text}: is a symbolic link; give the folder itself"
    if not stat.S_ISDIR(mode):
        return f"{text}: is a file, not a folder"
    try:
        foreign = sorted(e for e in os.listdir(path) if e not in RUN_FILES)
    except FileNotFoundError:  # moved aside since the look above: absent
        return None
    except OSError as exc:
        return f"{text}: cannot be read ({exc.strerror or exc})"
    if foreign:
        shown = ", ".join(foreign[:3]) + (", ..." if len(foreign) > 3 else "")
        return (f"{text}: holds {len(foreign)} entr{'y' if len(foreign) == 1 else 'ies'} that a run folder "
                f"does not ({shown}); choose an empty folder or a run folder")
    return None


def prepare_run_folder(folder: str | os.PathLike) -> Path:
    """Check that a run can be written to ``folder``, before the run: create its parents, test writing.

    Parameters
    ----------
    folder : str or path-like
        The intended run folder.

    Returns
    -------
    pathlib.Path
        ``folder`` as a path.

    Raises
    ------
    FolderError
        One line: see :func:`run_folder_problem`, or a parent that cannot be created or written.
    """
    problem = run_folder_problem(folder)
    if problem is not None:
        raise FolderError(problem)
    path = Path(folder)
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        make_temp_folder(path).rmdir()
    except OSError as exc:
        where = exc.filename if isinstance(exc.filename, str) else path.parent
        raise FolderError(f"{os.fspath(folder)}: cannot write there ({where}: {exc.strerror or exc})") from None
    return path


def verify_run_folder(folder: str | os.PathLike) -> list[str]:
    """Check that a run folder is one run's complete output: every file ``run.json`` lists matches.

    Parameters
    ----------
    folder : str or path-like
        A folder written by :meth:`Result.save`.

    Returns
    -------
    list of str
        Problems found (empty: consistent): a missing or unreadable ``run.json``, a listed file
        missing or with another SHA-256 or size, an entry that is not a run-folder file.
    """
    path = Path(folder)
    try:
        doc = json.loads((path / JSON_NAME).read_text(encoding="utf-8"))
    except (OSError, ValueError) as exc:
        return [f"{JSON_NAME}: cannot be read ({exc})"]
    problems = []
    for name, rec in (doc.get("files") or {}).items():
        try:
            data = (path / name).read_bytes()
        except OSError as exc:
            problems.append(f"{name}: missing ({exc.strerror or exc})")
            continue
        if len(data) != rec.get("bytes") or hashlib.sha256(data).hexdigest() != rec.get("sha256"):
            problems.append(f"{name}: does not match the SHA-256 and size recorded in {JSON_NAME}")
    extra = sorted(e for e in os.listdir(path) if e not in RUN_FILES)
    if extra:
        problems.append(f"entries that are not run-folder files: {', '.join(extra)}")
    return problems


class _HashingWriter:
    """A binary file wrapper that also computes the SHA-256 and size of what is written."""

    def __init__(self, fh: BinaryIO) -> None:
        self.fh, self.sha, self.size = fh, hashlib.sha256(), 0

    def write(self, data: bytes) -> None:
        self.fh.write(data)
        self.sha.update(data)
        self.size += len(data)

    def record(self) -> dict[str, Any]:
        return {"sha256": self.sha.hexdigest(), "bytes": self.size}


def csv_column(values: np.ndarray):
    """One CSV column: Arrow's shortest round-trip text of each float64, whole numbers with ``.0``.

    Arrow writes each value as the shortest decimal string that reads back to the same bits
    (positional or exponent form, whichever is shorter: ``0.25``, ``1e-7``, ``1e+15``; ``nan``,
    ``inf``, ``-inf``); a whole number it writes without a point (``0``, ``-3``) gets ``.0`` here,
    so that every column reads back as floats (``pandas.read_csv`` would make an all-``0``
    column integers).

    Parameters
    ----------
    values : numpy.ndarray
        A 1-D float64 column (or a block of it).

    Returns
    -------
    pyarrow.Array
        The floats themselves when no value is a whole number, else their text.
    """
    import pyarrow as pa
    import pyarrow.compute as pc

    v = np.ascontiguousarray(values, dtype=np.float64)
    col = pa.array(v)
    with np.errstate(invalid="ignore"):
        whole = np.isfinite(v) & (v == np.trunc(v))
    if not whole.any():
        return col
    text = pc.cast(col, pa.string())
    plain = pc.and_(pa.array(whole), pc.invert(pc.match_substring(text, "e")))  # "3", not "3e+20"
    return pc.if_else(plain, pc.binary_join_element_wise(text, ".0", ""), text)


# ---------------------------------------------------------------- Result
class Result:
    """Result of one simulation, modelled on python-control's response objects.

    Parameters
    ----------
    channels : mapping of str to array_like
        Equal-length 1-D arrays, insertion-ordered, starting with :data:`BASE_CHANNELS`
        (``t, x, y, z, theta, psi, u, v, w, q, r, tau_u, tau_q, tau_r, xd, yd, zd, ex, ey, ez``),
        optionally followed by extra channels (``rho_x``, ``chi_hat_x``, ``sliding_x``...).  Names must
        be identifiers of at most 63 characters (valid CSV headers and MATLAB variables).
    scenario : mapping
        The resolved scenario (JSON-compatible dict).
    status : {"ok", "failed", "interrupted"}
        Outcome of the run (``"interrupted"``: stopped by the user, e.g. Ctrl-C).
    failure : dict or None
        ``None`` for an ``ok`` run, else ``{"time", "cause", "detail", "state"}``.
    metrics : mapping of str to float
        Named metrics (:data:`auvtrack.metrics.METRIC_NAMES`); ``None`` is read as NaN.
    meta : dict, optional
        Anything else worth recording (wall time, notes...).
    version : str, optional
        Version of auvtrack that produced the run (default: the running version).

    Attributes
    ----------
    scenario : dict
    status : str
    failure : dict or None
    metrics : dict of str to float
    meta : dict
    version : str

    Raises
    ------
    ValueError
        On missing or misordered base channels, bad names, unequal lengths, non-1-D arrays, an
        unknown status or a failure record inconsistent with the status.

    Examples
    --------
    >>> import auvtrack
    >>> res = auvtrack.simulate("scenarios/paper.toml")  # doctest: +SKIP
    >>> res.to_pandas()[["t", "ex"]].tail()  # doctest: +SKIP
    >>> res.plot("errors").savefig("errors.png")  # doctest: +SKIP
    >>> res.save("runs/paper", mat=True)  # doctest: +SKIP
    """

    def __init__(self, channels: Mapping[str, Any], scenario: Mapping[str, Any], status: str,
                 failure: Mapping[str, Any] | None, metrics: Mapping[str, Any],
                 meta: Mapping[str, Any] | None = None, *, version: str | None = None) -> None:
        self._ch: dict[str, np.ndarray] = {}
        n = None
        for name, values in channels.items():
            if not isinstance(name, str) or not _NAME_RE.match(name):
                raise ValueError(f"invalid channel name {name!r}: use an identifier of at most 63 characters")
            arr = np.array(values, dtype=np.float64)  # a private copy
            if arr.ndim != 1:
                raise ValueError(f"channel {name!r} must be 1-D, got shape {arr.shape}")
            if n is None:
                n = arr.size
            elif arr.size != n:
                raise ValueError(f"channel {name!r} has {arr.size} samples, expected {n}")
            arr.flags.writeable = False
            self._ch[name] = arr
        head = tuple(self._ch)[:len(BASE_CHANNELS)]
        if head != BASE_CHANNELS:
            raise ValueError(f"channels must start with {', '.join(BASE_CHANNELS)}; got {', '.join(head)}")
        if status not in STATUSES:
            raise ValueError(f"status must be one of {STATUSES}, got {status!r}")
        if (status == "ok") != (failure is None):
            raise ValueError("failure must be None exactly when status is 'ok'")
        if failure is not None:
            missing = [k for k in FAILURE_KEYS if k not in failure]
            if missing:
                raise ValueError(f"failure record lacks {', '.join(missing)}")
        self.scenario: dict[str, Any] = dict(scenario)
        self.status: str = status
        self.failure: dict[str, Any] | None = None if failure is None else dict(failure)
        self.metrics: dict[str, float] = {k: math.nan if v is None else float(v) for k, v in metrics.items()}
        self.meta: dict[str, Any] = dict(meta or {})
        if version is None:
            from .. import __version__ as version
        self.version: str = str(version)

    # ---- access
    @property
    def t(self) -> np.ndarray:
        """Time samples (s)."""
        return self._ch["t"]

    @property
    def names(self) -> tuple[str, ...]:
        """Channel names, in order."""
        return tuple(self._ch)

    @property
    def channels(self) -> dict[str, np.ndarray]:
        """A new dict of the (read-only) channel arrays, in order."""
        return dict(self._ch)

    @property
    def ok(self) -> bool:
        """Whether the run completed without failure."""
        return self.status == "ok"

    @property
    def notes(self) -> tuple[str, ...]:
        """The set-up notes of the run (e.g. an initial envelope widening), from ``meta["notes"]``."""
        return tuple(str(n) for n in self.meta.get("notes", ()))

    @property
    def duration(self) -> float:
        """Logged time span ``t[-1] - t[0]`` (s); 0 for fewer than two samples."""
        t = self.t
        return float(t[-1] - t[0]) if t.size > 1 else 0.0

    def __getitem__(self, name: str) -> np.ndarray:
        """Return channel ``name`` (read-only array)."""
        try:
            return self._ch[name]
        except KeyError:
            raise KeyError(f"no channel {name!r}; available: {', '.join(self._ch)}") from None

    def __contains__(self, name: object) -> bool:
        """Whether a channel called ``name`` exists."""
        return name in self._ch

    def __iter__(self) -> Iterator[str]:
        """Iterate over channel names."""
        return iter(self._ch)

    def __len__(self) -> int:
        """Number of samples."""
        return int(self.t.size)

    @property
    def tracks(self) -> bool:
        """Whether the run's controller tracks a reference (an open-loop run flies a manoeuvre instead).

        An open-loop result carries ``meta["manoeuvre"]``; a result without it is asked of the
        controller's registered record (a plug-in's or an unknown kind counts as tracking).
        """
        if "manoeuvre" in self.meta:
            return False
        ctrl = self.scenario.get("controller") if isinstance(self.scenario, Mapping) else None
        kind = ctrl.get("kind") if isinstance(ctrl, Mapping) else None
        from ..control import get

        try:
            return bool(get(kind).tracks) if isinstance(kind, str) and kind != "plugin" else True
        except (KeyError, ValueError):
            return True

    def __repr__(self) -> str:
        """Short summary: status, controller, time span, key metrics (an open-loop run: its manoeuvre, no tracking error)."""
        from .manoeuvre import manoeuvre_line
        from .plotting import run_label

        t = self.t
        span = f"t={t[0]:g}..{t[-1]:g} s" if t.size else "no samples"
        parts = [f"status={self.status!r}"]
        if self.failure is not None:
            parts[0] += f" at t={self.failure.get('time', math.nan):.6g} s ({self.failure.get('cause')})"
        parts += [f"controller={run_label(self)!r}", f"{span}, {t.size} samples, {len(self._ch)} channels"]
        m = self.metrics
        if not self.tracks:
            flown = self.meta.get("manoeuvre")
            parts.append(manoeuvre_line(flown) if flown else "open loop (no manoeuvre recognised)")
        elif all(f"rmse_{a}" in m for a in "xyz"):
            parts.append("rmse[m]=(" + ", ".join(f"{a} {m[f'rmse_{a}']:.3g}" for a in "xyz") + ")")
        if all(f"max_abs_tau_{j}" in m for j in "uqr"):
            parts.append("max|tau|=(" + ", ".join(f"{j} {m[f'max_abs_tau_{j}']:.3g}" for j in "uqr") + ")")
        if self.notes:
            parts.append(f"{len(self.notes)} note{'s' if len(self.notes) > 1 else ''} (.notes)")
        return f"Result({', '.join(parts)})"

    # ---- conversion
    def to_pandas(self):
        """Return the channels as a :class:`pandas.DataFrame`.

        Returns
        -------
        pandas.DataFrame
            One column per channel, in order (``t`` first), one row per sample.
        """
        import pandas as pd

        cols = {k: np.array(v) for k, v in self._ch.items()}
        return pd.DataFrame(cols, columns=list(cols))

    def plot(self, kind: str = "overview", **kw: Any):
        """Draw this result (see :mod:`auvtrack.simulation.plotting`).

        Parameters
        ----------
        kind : {"overview", "trajectory3d", "positions", "velocities", "inputs", "errors", "chi"}
            Figure to draw.
        **kw
            ``label`` (legend label; default the controller kind) and keyword arguments of the
            ``fig_<kind>`` function (``figsize``, ``title``, ``t_range``...).

        Returns
        -------
        matplotlib.figure.Figure
            A new figure; never shown (headless-safe).
        """
        from .plotting import plot_runs, run_label

        label = kw.pop("label", None) or run_label(self)
        return plot_runs(kind, [(label, self)], **kw)

    # ---- run folder
    def _json_document(self, files: Mapping[str, Any] | None = None) -> str:
        nonfinite: dict[str, str] = {}
        doc = {"version": self.version, "status": self.status}
        body = {"failure": self.failure, "metrics": self.metrics, "scenario": self.scenario, "meta": self.meta}
        for key, value in body.items():
            doc[key] = to_jsonable(value, nonfinite, f"/{key}")
        doc["nonfinite"] = nonfinite
        if files is not None:
            doc["files"] = dict(files)
        return json.dumps(doc, indent=2, allow_nan=False, ensure_ascii=False) + "\n"

    def _write_csv(self, fh, stop: Callable[[], bool] | None = None) -> int:
        """Stream the CSV in blocks of :data:`CSV_BLOCK_ROWS` rows (memory flat in the run length).

        Before each block ``stop()`` is asked whether to end there; returns the rows written.
        """
        import pyarrow as pa
        import pyarrow.csv as pa_csv

        fh.write((",".join(self._ch) + "\n").encode("utf-8"))
        arrays = list(self._ch.values())
        names = [f"c{j}" for j in range(len(arrays))]  # the header is written above, unquoted
        options = pa_csv.WriteOptions(include_header=False, quoting_style="none")
        for start in range(0, len(self), CSV_BLOCK_ROWS):
            if stop is not None and stop():
                return start
            block = pa.table([csv_column(v[start:start + CSV_BLOCK_ROWS]) for v in arrays], names=names)
            sink = pa.BufferOutputStream()
            pa_csv.write_csv(block, sink, options)
            fh.write(sink.getvalue().to_pybytes())
        return len(self)

    def _csv_text(self) -> str:
        import io

        buf = io.BytesIO()
        self._write_csv(buf)
        return buf.getvalue().decode("utf-8")

    def scenario_toml(self) -> str | None:
        """The run's scenario as TOML (``scenario.toml``), or None for a result without a scenario.

        Returns
        -------
        str or None
            The resolved scenario without the derived ``resolved`` record (which ``run.json``
            keeps); ``auvtrack run`` accepts it as is.
        """
        from ..scenario.toml_writer import dumps

        doc = {k: v for k, v in self.scenario.items() if k != "resolved"}
        if not doc:
            return None
        header = (f"Fully resolved scenario of this run (auvtrack {self.version}).\n"
                  "`auvtrack run scenario.toml` reproduces trajectory.csv byte for byte\n"
                  "(same auvtrack version and machine); see docs/scenarios.md.")
        return dumps(doc, header=header)

    def save(self, out_dir: str | os.PathLike, mat: bool = False, *, overwrite: bool = True,
             stop: Callable[[], bool] | None = None) -> Path:
        """Write the run folder: ``trajectory.csv``, ``run.json``, ``scenario.toml``, optionally ``trajectory.mat``.

        Parameters
        ----------
        out_dir : str or path
            The run folder.  Its parents are created; an existing folder is replaced as a whole,
            and only if it is empty or holds nothing but run-folder files (:data:`RUN_FILES`).
        mat : bool, optional
            Also write ``trajectory.mat`` (MATLAB v5).
        overwrite : bool, optional
            False: never replace a folder; when ``out_dir`` is taken (by the time the run is
            published), use the first free ``<out_dir>-2``, ``-3``, ... instead (the default run
            folders of ``auvtrack run``).
        stop : callable, optional
            Asked between blocks of :data:`CSV_BLOCK_ROWS` rows (``auvtrack run`` passes "was
            Ctrl-C pressed"): when it returns True the CSV ends at that block, ``trajectory.mat``
            is skipped, and the folder is still completed and published, ``run.json`` recording
            ``"rows"`` (written) and ``"rows_in_result"`` under ``files["trajectory.csv"]``.

        Returns
        -------
        pathlib.Path
            The folder written (``out_dir``, or a numbered sibling with ``overwrite=False``).

        Raises
        ------
        FolderError
            ``out_dir`` is a file, a symbolic link, a folder holding other files, or cannot be
            written (checked before anything is written; :func:`prepare_run_folder`).

        Notes
        -----
        The files are written into a new, uniquely named folder next to ``out_dir`` (created
        exclusively: no existing file or symlink is ever opened) and that folder is renamed into
        place atomically, so ``out_dir`` is always absent or one run's complete output, even
        when several runs save to it at once (the last one to finish wins).  ``run.json`` records
        the SHA-256 and size of the other files under ``"files"``.

        CSV values are the shortest decimal strings that read back to the same bits
        (:func:`csv_column`; ``nan``, ``inf`` spelled so): loading gives the same bits, and
        identical results give byte-identical files.  In ``run.json`` every non-finite
        float is written as ``null`` and its JSON pointer recorded under ``"nonfinite"``
        (e.g. ``{"/metrics/settle_1mm_x": "inf"}``) so that :meth:`load` restores it.
        """
        folder = prepare_run_folder(out_dir)
        tmp = make_temp_folder(folder)
        try:
            files: dict[str, Any] = {}
            with open_exclusive(tmp / CSV_NAME) as fh:
                w = _HashingWriter(fh)
                rows = self._write_csv(w, stop)
                files[CSV_NAME] = w.record()
            if rows < len(self):
                files[CSV_NAME].update(rows=rows, rows_in_result=len(self))
            toml = self.scenario_toml()
            if toml is not None:
                data = toml.encode("utf-8")
                with open_exclusive(tmp / TOML_NAME) as fh:
                    fh.write(data)
                files[TOML_NAME] = {"sha256": hashlib.sha256(data).hexdigest(), "bytes": len(data)}
            if mat and rows == len(self):
                self._save_mat(tmp / MAT_NAME)
            with open_exclusive(tmp / JSON_NAME) as fh:
                fh.write(self._json_document(files).encode("utf-8"))
        except BaseException:
            shutil.rmtree(tmp, ignore_errors=True)
            raise
        if not overwrite:
            return publish_new_folder(tmp, (folder if n == 1 else folder.with_name(f"{folder.name}-{n}")
                                            for n in itertools.count(1)))
        publish_folder(tmp, folder, run_folder_problem)
        return folder

    def _save_mat(self, path: Path) -> None:
        from scipy.io import savemat

        clash = [n for n in self._ch if n in MAT_RESERVED]
        if clash:
            raise ValueError(f"channel names {clash} clash with trajectory.mat variables")
        bad = [k for k in self.metrics if not _NAME_RE.match(k)]
        if bad:
            raise ValueError(f"metric names {bad} are not valid MATLAB field names")
        mdict: dict[str, Any] = {n: v.reshape(-1, 1) for n, v in self._ch.items()}
        mdict["channel_names"] = np.array(list(self._ch), dtype=object)
        mdict["scenario_json"] = json.dumps(to_jsonable(self.scenario), allow_nan=False)
        mdict["failure_json"] = json.dumps(to_jsonable(self.failure), allow_nan=False)
        mdict["status"] = self.status
        mdict["version"] = self.version
        mdict["metrics"] = {k: float(v) for k, v in self.metrics.items()}
        with open_exclusive(path) as f:
            savemat(f, mdict, oned_as="column")

    @classmethod
    def load(cls, run_dir: str | os.PathLike) -> "Result":
        """Read a run folder written by :meth:`save`.

        Parameters
        ----------
        run_dir : str or path
            Folder holding ``trajectory.csv`` and ``run.json``.

        Returns
        -------
        Result
            Channels bit-identical to the saved ones; non-finite JSON values restored.

        Raises
        ------
        FileNotFoundError
            If a file is missing.
        ValueError
            If the files are inconsistent.
        """
        folder = Path(run_dir)
        doc = json.loads((folder / JSON_NAME).read_text(encoding="utf-8"))
        restore_nonfinite(doc, doc.pop("nonfinite", None) or {})
        lines = (folder / CSV_NAME).read_text(encoding="utf-8").splitlines()
        if not lines:
            raise ValueError(f"{folder / CSV_NAME} is empty")
        names = lines[0].split(",")
        if len(lines) > 1:
            data = np.loadtxt(lines[1:], delimiter=",", dtype=np.float64, ndmin=2)
        else:
            data = np.zeros((0, len(names)))
        if data.shape[1] != len(names):
            raise ValueError(f"{folder / CSV_NAME}: {data.shape[1]} columns but {len(names)} names")
        channels = {n: data[:, j] for j, n in enumerate(names)}
        return cls(channels, doc.get("scenario") or {}, doc["status"], doc.get("failure"),
                   doc.get("metrics") or {}, doc.get("meta"), version=doc.get("version"))


__all__ = ["Result", "csv_column", "BASE_CHANNELS", "RUN_FILES", "to_jsonable", "restore_nonfinite", "run_folder_problem",
           "prepare_run_folder", "verify_run_folder", "FolderError"]
