"""The outcome of one simulation: logged channels, metrics, status, and the run-folder format.

A run folder holds ``trajectory.csv`` (bit-exact text), ``run.json`` (scenario, status, failure,
metrics, meta) and optionally ``trajectory.mat``; ``docs/metrics.md`` is the contract.
"""
from __future__ import annotations

import json
import math
import os
import re
from pathlib import Path
from typing import Any, Iterator, Mapping

import numpy as np

from .channels import current_name, legacy_columns, upgrade_names

BASE_CHANNELS: tuple[str, ...] = ("t", "x", "y", "z", "theta", "psi", "u", "v", "w", "q", "r",
                                  "tau_u", "tau_q", "tau_r", "xd", "yd", "zd", "ex", "ey", "ez")
"""Channels every result starts with, in this order (SI units: s, m, rad, m/s, rad/s, N, N m)."""

STATUSES = ("ok", "failed", "interrupted")
FAILURE_KEYS = ("time", "cause", "detail", "state")
CSV_NAME, JSON_NAME, MAT_NAME = "trajectory.csv", "run.json", "trajectory.mat"
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


def _atomic_write(path: Path, data: str | bytes) -> None:
    tmp = path.with_name(path.name + ".tmp")
    if isinstance(data, str):
        tmp.write_text(data, encoding="utf-8", newline="\n")
    else:
        tmp.write_bytes(data)
    os.replace(tmp, path)


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
    status : {"ok", "failed"}
        Outcome of the run.
    failure : dict or None
        ``None`` for an ``ok`` run, else ``{"time", "cause", "detail", "state"}``.
    metrics : mapping of str to float
        Named metrics (:data:`auvtrack.simulation.metrics.METRIC_NAMES`); ``None`` is read as NaN.
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
    def duration(self) -> float:
        """Logged time span ``t[-1] - t[0]`` (s); 0 for fewer than two samples."""
        t = self.t
        return float(t[-1] - t[0]) if t.size > 1 else 0.0

    def __getitem__(self, name: str) -> np.ndarray:
        """Return channel ``name`` (read-only array); an old channel name warns and still works."""
        try:
            return self._ch[name]
        except KeyError:
            new = current_name(name, self._ch, self._kind())
            if new is not None:
                return self._ch[new]
            raise KeyError(f"no channel {name!r}; available: {', '.join(self._ch)}") from None

    def __contains__(self, name: object) -> bool:
        """Whether a channel called ``name`` exists (old channel names included, see ``channels``)."""
        return name in self._ch or (isinstance(name, str) and
                                    current_name(name, self._ch, self._kind(), warn=False) is not None)

    def _kind(self) -> str | None:
        ctrl = self.scenario.get("controller")
        return ctrl.get("kind") if isinstance(ctrl, Mapping) else None

    def __iter__(self) -> Iterator[str]:
        """Iterate over channel names."""
        return iter(self._ch)

    def __len__(self) -> int:
        """Number of samples."""
        return int(self.t.size)

    def __repr__(self) -> str:
        """Short summary: status, controller, time span, key metrics."""
        from .plotting import run_label

        t = self.t
        span = f"t={t[0]:g}..{t[-1]:g} s" if t.size else "no samples"
        parts = [f"status={self.status!r}"]
        if self.failure is not None:
            parts[0] += f" at t={self.failure.get('time', math.nan):.6g} s ({self.failure.get('cause')})"
        parts += [f"controller={run_label(self)!r}", f"{span}, {t.size} samples, {len(self._ch)} channels"]
        m = self.metrics
        if all(f"rmse_{a}" in m for a in "xyz"):
            parts.append("rmse[m]=(" + ", ".join(f"{a} {m[f'rmse_{a}']:.3g}" for a in "xyz") + ")")
        if all(f"max_abs_tau_{j}" in m for j in "uqr"):
            parts.append("max|tau|=(" + ", ".join(f"{j} {m[f'max_abs_tau_{j}']:.3g}" for j in "uqr") + ")")
        return f"Result({', '.join(parts)})"

    # ---- conversion
    def to_pandas(self, legacy_names: bool = True):
        """Return the channels as a :class:`pandas.DataFrame`.

        Parameters
        ----------
        legacy_names : bool, optional
            Also add the renamed channels under their old names (``S_x``, ``z_x`` of the FXTNTSMC,
            ``s_x`` of the FTSMC), after every channel.  Deprecated: these columns disappear in
            the next release (:mod:`auvtrack.simulation.channels`); pass ``False`` to drop them now.

        Returns
        -------
        pandas.DataFrame
            One column per channel, in order (``t`` first), one row per sample, then the old
            names, if any.
        """
        import pandas as pd

        cols = {k: np.array(v) for k, v in self._ch.items()}
        if legacy_names:
            cols.update({old: np.array(self._ch[new]) for old, new in legacy_columns(self._ch, self._kind()).items()})
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
    def _json_document(self) -> str:
        nonfinite: dict[str, str] = {}
        doc = {"version": self.version, "status": self.status}
        body = {"failure": self.failure, "metrics": self.metrics, "scenario": self.scenario, "meta": self.meta}
        for key, value in body.items():
            doc[key] = to_jsonable(value, nonfinite, f"/{key}")
        doc["nonfinite"] = nonfinite
        return json.dumps(doc, indent=2, allow_nan=False, ensure_ascii=False) + "\n"

    def _csv_text(self) -> str:
        # repr of a Python float is the shortest string that round-trips bit-exactly
        cols = [list(map(repr, v.tolist())) for v in self._ch.values()]
        rows = [",".join(r) + "\n" for r in zip(*cols)]
        return ",".join(self._ch) + "\n" + "".join(rows)

    def save(self, out_dir: str | os.PathLike, mat: bool = False) -> Path:
        """Write the run folder: ``trajectory.csv``, ``run.json`` and optionally ``trajectory.mat``.

        Parameters
        ----------
        out_dir : str or path
            Folder to create (parents too) or overwrite.
        mat : bool, optional
            Also write ``trajectory.mat`` (MATLAB v5); otherwise a stale one is removed.

        Returns
        -------
        pathlib.Path
            The folder.

        Notes
        -----
        CSV values are Python float reprs (``nan``, ``inf`` spelled so): loading gives the same
        bits, and identical results give byte-identical files.  In ``run.json`` every non-finite
        float is written as ``null`` and its JSON pointer recorded under ``"nonfinite"``
        (e.g. ``{"/metrics/settle_1mm_x": "inf"}``) so that :meth:`load` restores it.
        """
        folder = Path(out_dir)
        folder.mkdir(parents=True, exist_ok=True)
        _atomic_write(folder / CSV_NAME, self._csv_text())
        _atomic_write(folder / JSON_NAME, self._json_document())
        mat_path = folder / MAT_NAME
        if mat:
            self._save_mat(mat_path)
        elif mat_path.exists():
            mat_path.unlink()
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
        tmp = path.with_name(path.name + ".tmp")
        with open(tmp, "wb") as f:
            savemat(f, mdict, oned_as="column")
        os.replace(tmp, path)

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
        ctrl = (doc.get("scenario") or {}).get("controller")
        names = upgrade_names(lines[0].split(","), ctrl.get("kind") if isinstance(ctrl, Mapping) else None)
        if len(lines) > 1:
            data = np.loadtxt(lines[1:], delimiter=",", dtype=np.float64, ndmin=2)
        else:
            data = np.zeros((0, len(names)))
        if data.shape[1] != len(names):
            raise ValueError(f"{folder / CSV_NAME}: {data.shape[1]} columns but {len(names)} names")
        channels = {n: data[:, j] for j, n in enumerate(names)}
        return cls(channels, doc.get("scenario") or {}, doc["status"], doc.get("failure"),
                   doc.get("metrics") or {}, doc.get("meta"), version=doc.get("version"))


__all__ = ["Result", "BASE_CHANNELS", "to_jsonable", "restore_nonfinite"]
