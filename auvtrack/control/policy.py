"""A learned policy: an MLP read from one ``.npz`` file, evaluated inside the compiled law.

u = scale * clip(f((obs - mean) / std), -1, 1), with obs the observation the Gymnasium
environment gives (:mod:`auvtrack.control.policy_observation`, one function for both) and f the
network: layers ``W_l h + b_l`` each followed by its activation (``identity``, ``tanh``, ``relu``).

The file holds ``header`` (JSON: format, version, ``commands``, ``scale``, ``activations``,
``provenance``), ``W0, b0, W1, b1, ...``, ``obs_mean`` and ``obs_std`` (:func:`save_policy`,
:func:`load_policy`).  ``controller.file`` is a ``.npz`` path or the name of a policy shipped in
``auvtrack/data/policies`` (:func:`available_policies`; default :data:`DEFAULT_POLICY`).  Packed :data:`HEAD` then the sizes, activation codes, scale, normalisation
and the weights; the hidden activations use the law's scratch.
"""
from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any, Literal

import numpy as np
from pydantic import Field

from ..jit import njit
from ..packing import packed_layout
from .contract import WORK_SIZE
from .policy_observation import OBS, OBS_BOUND, observe
from .registry import CompiledController, ControllerParams

NAME = "policy"
AUX_NAMES: tuple[str, ...] = ()
COMMANDS = "tau"
ACTIVATIONS = ("identity", "tanh", "relu")
FORMAT = "auvtrack-policy"
HEAD = packed_layout("PolicyHead", n_layers=1, rest=None)
SHIPPED = Path(__file__).resolve().parents[1] / "data" / "policies"
DEFAULT_POLICY = "remus100-cmaes"
"""The shipped policy ``controller.kind = "policy"`` flies without a ``file``."""
DEFAULT_ACTUATOR_POLICY = "policy.npz"
"""What ``controller.kind = "policy_actuators"`` flies without a ``file`` (no actuator policy is shipped)."""
COMMAND_KINDS = ("tau", "actuators")
"""What a policy file's outputs command: tau (N, N m, N m) or the actuators (rpm, rad, rad)."""


def available_policies() -> list[str]:
    """Names of the policies shipped with the package.

    Returns
    -------
    list of str
        Sorted names (files ``auvtrack/data/policies/<name>.npz``).
    """
    return sorted(p.stem for p in SHIPPED.glob("*.npz"))


def policy_path(file: str | Path) -> Path:
    """The file of a policy: a shipped name (no suffix, no folder) or a path.

    Parameters
    ----------
    file : str or Path
        Name or path.

    Returns
    -------
    Path
        The ``.npz`` file (not checked to exist).
    """
    p = Path(file)
    if p.suffix == "" and p.parent == Path("."):
        return SHIPPED / f"{p.name}.npz"
    return p.expanduser()


class Params(ControllerParams):
    """A policy: a shipped name or a ``.npz`` file (:func:`save_policy`)."""

    kind: Literal["policy"] = "policy"
    file: str = Field(DEFAULT_POLICY, min_length=1,
                      description="a shipped policy's name (auvtrack/data/policies) or a .npz file")


def save_policy(path: str | Path, weights, biases, activations, scale, obs_mean=None, obs_std=None,
                provenance: dict | None = None, commands: str = "tau") -> Path:
    """Write a policy file.

    Parameters
    ----------
    path : str or Path
        Destination ``.npz``.
    weights, biases : sequence of numpy.ndarray
        Layer l: ``W_l`` (out, in) and ``b_l`` (out,); the first layer's input is ``OBS.size``, the
        last layer's output 3.
    activations : sequence of str
        One of :data:`ACTIVATIONS` per layer.
    scale : sequence of 3 float
        Command per unit action.
    obs_mean, obs_std : numpy.ndarray, optional
        Observation normalisation (default 0 and 1).
    provenance : dict, optional
        How it was made (command, budget, seed).
    commands : str, optional
        ``"tau"`` (default; ``controller.kind = "policy"``) or ``"actuators"`` (the outputs are
        (rpm, stern plane, rudder) of a 6-DOF plant; ``controller.kind = "policy_actuators"``).

    Returns
    -------
    Path
        The file written.
    """
    weights = [np.asarray(w, float) for w in weights]
    biases = [np.asarray(b, float) for b in biases]
    if commands not in COMMAND_KINDS:
        raise ValueError(f"commands: must be one of {', '.join(COMMAND_KINDS)} (got {commands!r})")
    header = {"format": FORMAT, "version": 1, "commands": commands, "scale": [float(s) for s in scale],
              "activations": list(activations), "provenance": provenance or {}}
    arrays = {f"W{i}": w for i, w in enumerate(weights)} | {f"b{i}": b for i, b in enumerate(biases)}
    arrays["obs_mean"] = np.zeros(OBS.size) if obs_mean is None else np.asarray(obs_mean, float)
    arrays["obs_std"] = np.ones(OBS.size) if obs_std is None else np.asarray(obs_std, float)
    path = Path(path)
    with open(path, "wb") as f:
        np.savez(f, header=np.array(json.dumps(header)), **arrays)
    load_policy(path)  # refuses what it wrote if malformed
    return path


def load_policy(path: str | Path) -> dict[str, Any]:
    """Read and check a policy file.

    Parameters
    ----------
    path : str or Path
        The ``.npz`` file or a shipped policy's name (:func:`policy_path`).

    Returns
    -------
    dict
        ``header``, ``weights``, ``biases``, ``obs_mean``, ``obs_std``.

    Raises
    ------
    ValueError
        One line naming what is wrong.
    """
    path = policy_path(path)
    if not path.is_file():
        shipped = ", ".join(available_policies()) or "none"
        raise ValueError(f"controller.file: no policy file {str(path)!r} (shipped policies: {shipped})")
    try:
        with np.load(path, allow_pickle=False) as z:
            data = {k: z[k] for k in z.files}
    except (OSError, ValueError) as exc:
        raise ValueError(f"controller.file: cannot read a policy from {path} ({exc})") from None
    header = json.loads(str(data.get("header", "{}")))
    if header.get("format") != FORMAT:
        raise ValueError(f"controller.file: {path} is not an {FORMAT} file")
    acts = header.get("activations", [])
    n = len(acts)
    weights = [data.get(f"W{i}") for i in range(n)]
    biases = [data.get(f"b{i}") for i in range(n)]
    if n == 0 or any(w is None or w.ndim != 2 for w in weights) or any(b is None for b in biases):
        raise ValueError(f"controller.file: {path}: needs W0, b0, ... one pair per activation")
    size = OBS.size
    for i, (w, b) in enumerate(zip(weights, biases)):
        if w.shape[1] != size or b.shape != (w.shape[0],):
            raise ValueError(f"controller.file: {path}: layer {i} has shape {w.shape}, expected (*, {size})")
        size = w.shape[0]
    if size != 3 or any(a not in ACTIVATIONS for a in acts):
        raise ValueError(f"controller.file: {path}: the last layer must output 3 values, activations one of "
                         f"{', '.join(ACTIVATIONS)}")
    if max(w.shape[0] for w in weights) > WORK_SIZE // 2 - OBS.size:
        raise ValueError(f"controller.file: {path}: layers wider than {WORK_SIZE // 2 - OBS.size} (the law's scratch)")
    std = np.asarray(data["obs_std"], float)
    if std.shape != (OBS.size,) or not np.all(std > 0) or np.asarray(data["obs_mean"]).shape != (OBS.size,):
        raise ValueError(f"controller.file: {path}: obs_mean, obs_std must have {OBS.size} entries, std > 0")
    if header.get("commands", "tau") not in COMMAND_KINDS:
        raise ValueError(f"controller.file: {path}: commands must be one of {', '.join(COMMAND_KINDS)}")
    every = [*weights, *biases, data["obs_mean"], std, np.asarray(header.get("scale", []), float)]
    if not all(np.all(np.isfinite(a)) for a in every) or len(header.get("scale", [])) != 3:
        raise ValueError(f"controller.file: {path}: non-finite numbers or a scale without 3 entries")
    return {"header": header, "weights": weights, "biases": biases, "obs_mean": np.asarray(data["obs_mean"], float),
            "obs_std": std}


def pack(policy: dict[str, Any]) -> np.ndarray:
    """The packed parameters of a loaded policy (layout in the module docstring).

    Parameters
    ----------
    policy : dict
        :func:`load_policy`'s result.

    Returns
    -------
    numpy.ndarray
        [n_layers, sizes (n_layers + 1), activation codes, scale (3), mean, std, W0, b0, W1, b1, ...].
    """
    ws, bs = policy["weights"], policy["biases"]
    sizes = [OBS.size] + [w.shape[0] for w in ws]
    codes = [ACTIVATIONS.index(a) for a in policy["header"]["activations"]]
    parts = [[len(ws)], sizes, codes, policy["header"]["scale"], policy["obs_mean"], policy["obs_std"]]
    for w, b in zip(ws, bs):
        parts += [w.ravel(), b]
    return np.concatenate([np.asarray(p, float).ravel() for p in parts])


def forward(policy: dict[str, Any], obs: np.ndarray) -> np.ndarray:
    """The command of a loaded policy at an observation (NumPy reference of the compiled law).

    Parameters
    ----------
    policy : dict
        :func:`load_policy`'s result.
    obs : numpy.ndarray
        (OBS.size,) observation.

    Returns
    -------
    numpy.ndarray
        (3,) command: scale * clip(output, -1, 1).
    """
    h = (np.asarray(obs, float) - policy["obs_mean"]) / policy["obs_std"]
    for w, b, a in zip(policy["weights"], policy["biases"], policy["header"]["activations"]):
        h = w @ h + b
        h = np.tanh(h) if a == "tanh" else np.maximum(h, 0.0) if a == "relu" else h
    return np.asarray(policy["header"]["scale"]) * np.clip(h, -1.0, 1.0)


@njit
def control(t, y, xc, args, out):
    """The network at the observation of the measured state (module docstring)."""
    cp, work = args.cp, args.work
    n = int(cp[0])
    at_codes = 1 + n + 1
    at_scale = at_codes + n
    at_mean = at_scale + 3
    at_std = at_mean + OBS.size
    at = at_std + OBS.size
    observe(t, y.eta, y.nu, y.att, args.path, args.applied, cp[at_scale:at_scale + 3], OBS_BOUND, work)
    for i in range(OBS.size):
        work[i] = (work[i] - cp[at_mean + i]) / cp[at_std + i]
    src, dst = 0, OBS.size
    for layer in range(n):
        n_in, n_out = int(cp[1 + layer]), int(cp[2 + layer])
        code = int(cp[at_codes + layer])
        b = at + n_out * n_in
        for r in range(n_out):
            s = cp[b + r]
            for c in range(n_in):
                s += cp[at + r * n_in + c] * work[src + c]
            if code == 1:
                s = math.tanh(s)
            elif code == 2 and s < 0.0:
                s = 0.0
            work[dst + r] = s
        at = b + n_out
        src, dst = dst, (OBS.size if dst != OBS.size else WORK_SIZE // 2)
    for i in range(3):
        v = work[src + i]
        out.u[i] = cp[at_scale + i] * (-1.0 if v < -1.0 else 1.0 if v > 1.0 else v)
    return 0


def setup(params: Params, ctx) -> CompiledController:
    """Load the policy file and pack it."""
    policy = load_policy(params.file)
    commands = policy["header"].get("commands", "tau")
    if commands != ctx.commands:
        kind = "policy_actuators" if commands == "actuators" else "policy"
        raise ValueError(f"controller.file: the policy commands {commands!r}, the law {ctx.commands!r} "
                         f"(controller.kind = {kind!r} flies it)")
    return CompiledController(cp=pack(policy), xc0=np.zeros(0),
                              resolved={"policy": {"file": str(policy_path(params.file)), **policy["header"]}})
